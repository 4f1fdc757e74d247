// SPDX-License-Identifier: LGPL-2.1-or-later
// Which EGL device a context is made on, without a GPU: the order deviceOrder() gives for
// devices described as NVIDIA's EGL describes them (a CUDA id each), and Mesa's (none).
#include <gtest/gtest.h>

#include "filter/gl/EglContext.hpp"

namespace defocus::gl {
namespace {

std::vector<DeviceInfo> nvidiaNode()
{
    // Four GPUs; the job was given physical GPUs 2 and 3 (CUDA_VISIBLE_DEVICES=2,3), so CUDA
    // numbers them 0 and 1 and the others have no CUDA id in this process; then Mesa's llvmpipe.
    std::vector<DeviceInfo> devices(5);
    for (int i = 0; i < 5; ++i)
        devices[static_cast<std::size_t>(i)].index = i;
    devices[2].cudaId = 0;
    devices[3].cudaId = 1;
    devices[4].software = true;
    return devices;
}

// Defect: a Slurm job given one GPU rendering on another job's GPU (EGL lists every GPU of the
// node whatever CUDA_VISIBLE_DEVICES says), i.e. the CUDA device not tried first.
TEST(EglDevices, CudaVisibleDevicesPutsCudasFirstGpuFirst)
{
    EXPECT_EQ(deviceOrder(nvidiaNode(), std::nullopt, std::string("2,3")), (std::vector<int>{2, 0, 1, 3, 4}));
}

// Defect: the default changed for machines without CUDA_VISIBLE_DEVICES (first device, then the
// others), or Mesa's devices, which have no CUDA id, reordered.
TEST(EglDevices, WithoutCudaTheDevicesKeepTheirOrder)
{
    EXPECT_EQ(deviceOrder(nvidiaNode(), std::nullopt, std::nullopt), (std::vector<int>{0, 1, 2, 3, 4}));
    EXPECT_EQ(deviceOrder(nvidiaNode(), std::nullopt, std::string()), (std::vector<int>{0, 1, 2, 3, 4}));
    std::vector<DeviceInfo> mesa(2);
    mesa[1].index = 1;
    mesa[1].software = true;
    EXPECT_EQ(deviceOrder(mesa, std::nullopt, std::string("0")), (std::vector<int>{0, 1}));
}

// Defect: --egl-device N falling back to another device (a job would silently share a GPU), or
// an index past the end accepted.
TEST(EglDevices, AnAskedForDeviceIsTheOnlyOneTried)
{
    EXPECT_EQ(deviceOrder(nvidiaNode(), 3, std::string("2")), (std::vector<int>{3}));
    EXPECT_TRUE(deviceOrder(nvidiaNode(), 5, std::nullopt).empty());
    EXPECT_TRUE(deviceOrder(nvidiaNode(), -1, std::nullopt).empty());
}

} // namespace
} // namespace defocus::gl
