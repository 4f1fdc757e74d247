// SPDX-License-Identifier: LGPL-2.1-or-later
// A webcam reader for the virtual-camera test in the VM (scripts/v4l2-vm-test.sh): captures YUYV
// frames from a v4l2loopback node while a writer (defocus -o /dev/videoN, or gst-launch-1.0 with
// v4l2sink) fills it, then checks each captured frame against the filter's output written as PNGs
// by the command line beforehand, in the YUYV domain, computed here from BT.601's equations.
//   v4l2-vcam-check DEVICE REF_DIR CHROMA [WAIT_S [DONE_FILE]]
//   v4l2-vcam-check prepare TUM_DIR COUNT OUT_DIR      (the test's input, on the host)
// CHROMA says where the writer samples chroma: "pair" (the mean of the two pixels, as
// V4l2OutputSink does) or "left" (the even pixel's, videoconvert chroma-mode=none).
// Exit 0 when every captured frame is one of the references within the bound, in order, and at
// most the first reference is missing; 1 otherwise; 2 for a bad command line.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace {

namespace fs = std::filesystem;

int xioctl(int fd, unsigned long request, void* arg)
{
    int result = 0;
    do
        result = ::ioctl(fd, request, arg);
    while (result == -1 && errno == EINTR);
    return result;
}

double y601(double r, double g, double b) { return 16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0; }
double cb601(double r, double g, double b) { return 128.0 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0; }
double cr601(double r, double g, double b) { return 128.0 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0; }

/// The largest difference between `yuyv` and the exact BT.601 values of `bgr`, in code values.
double worstError(const std::vector<std::uint8_t>& yuyv, const cv::Mat& bgr, bool pairChroma)
{
    double worst = 0.0;
    for (int y = 0; y < bgr.rows; ++y)
        for (int x = 0; x < bgr.cols; x += 2) {
            const cv::Vec3b p0 = bgr.at<cv::Vec3b>(y, x), p1 = bgr.at<cv::Vec3b>(y, x + 1);
            const std::uint8_t* q = &yuyv[static_cast<std::size_t>((y * bgr.cols + x) * 2)];
            double r = p0[2], g = p0[1], b = p0[0];
            if (pairChroma) {
                r = 0.5 * (p0[2] + p1[2]);
                g = 0.5 * (p0[1] + p1[1]);
                b = 0.5 * (p0[0] + p1[0]);
            }
            worst = std::max({worst, std::abs(q[0] - y601(p0[2], p0[1], p0[0])),
                              std::abs(q[2] - y601(p1[2], p1[1], p1[0])), std::abs(q[1] - cb601(r, g, b)),
                              std::abs(q[3] - cr601(r, g, b))});
        }
    return worst;
}

} // namespace

/// prepare TUM_DIR COUNT OUT_DIR: the first COUNT associated pairs of a TUM folder at half size
/// (colour by area averaging, depth by nearest neighbour, still 16-bit), as OUT_DIR/rgb/%06d.png and
/// OUT_DIR/depth/%06d.png: a quarter of the pixels makes the test's GL work under emulation short.
int prepare(const fs::path& tum, int count, const fs::path& out)
{
    std::FILE* list = std::fopen((tum / "associations.txt").c_str(), "r");
    if (!list)
        return std::printf("vcam-check: no %s\n", (tum / "associations.txt").c_str()), 1;
    fs::create_directories(out / "rgb");
    fs::create_directories(out / "depth");
    char rgb[256], depth[256];
    int n = 0;
    while (n < count && std::fscanf(list, "%*s %255s %*s %255s", rgb, depth) == 2) {
        const cv::Mat color = cv::imread((tum / rgb).string(), cv::IMREAD_COLOR);
        const cv::Mat d = cv::imread((tum / depth).string(), cv::IMREAD_UNCHANGED);
        if (color.empty() || d.empty())
            return std::printf("vcam-check: cannot read %s or %s\n", rgb, depth), 1;
        cv::Mat small, smallDepth;
        cv::resize(color, small, color.size() / 2, 0, 0, cv::INTER_AREA);
        cv::resize(d, smallDepth, d.size() / 2, 0, 0, cv::INTER_NEAREST);
        char name[32];
        std::snprintf(name, sizeof name, "%06d.png", n++);
        if (!cv::imwrite((out / "rgb" / name).string(), small) || !cv::imwrite((out / "depth" / name).string(), smallDepth))
            return std::printf("vcam-check: cannot write into %s\n", out.c_str()), 1;
    }
    std::fclose(list);
    return n == count ? 0 : 1;
}

int main(int argc, char** argv)
{
    if (argc == 5 && std::string(argv[1]) == "prepare")
        return prepare(argv[2], std::atoi(argv[3]), argv[4]);
    if (argc < 4) {
        std::fprintf(stderr, "usage: v4l2-vcam-check DEVICE REF_DIR pair|left [WAIT_S [DONE_FILE]]\n");
        return 2;
    }
    const std::string device = argv[1];
    const fs::path refDir = argv[2];
    const bool pairChroma = std::string(argv[3]) == "pair";
    const double waitS = argc > 4 ? std::atof(argv[4]) : 600.0;
    const fs::path doneFile = argc > 5 ? argv[5] : "";
    // pair: V4l2OutputSink rounds the exact values: half a code, plus 3e-4 for the equations'
    // coefficients printed to 3 decimals. left: videoconvert's 8-bit integer matrix holds each
    // coefficient to 1/256 (error <= 1/512 each, over three channels of up to 255: 1.5 codes)
    // and rounds the sum (0.5): 2 codes (measured on the bundled clip: 1.03 luma, 1.20 chroma).
    const double bound = pairChroma ? 0.5 + 1e-3 : 2.0 + 1e-3;

    std::vector<fs::path> refs;
    for (const auto& entry : fs::directory_iterator(refDir))
        if (entry.path().extension() == ".png")
            refs.push_back(entry.path());
    std::sort(refs.begin(), refs.end());
    if (refs.empty()) {
        std::printf("vcam-check: no reference PNGs in %s\n", refDir.c_str());
        return 1;
    }

    const int fd = ::open(device.c_str(), O_RDWR | O_NONBLOCK);
    if (fd < 0) {
        std::printf("vcam-check: cannot open %s: %s\n", device.c_str(), std::strerror(errno));
        return 1;
    }
    // The node has a capture format once the writer wrote its first frame: wait for it.
    v4l2_format format{};
    format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    int waited = 0;
    while (xioctl(fd, VIDIOC_G_FMT, &format) != 0) {
        if (waited++ > waitS * 50) {
            std::printf("vcam-check: %s got no writer in %.0f s\n", device.c_str(), waitS);
            return 1;
        }
        ::usleep(20000);
    }
    const auto& pix = format.fmt.pix;
    char fourcc[5] = {};
    std::memcpy(fourcc, &pix.pixelformat, 4);
    std::printf("vcam-check: %s gives %s %ux%u, %u bytes per line (after %.2f s)\n", device.c_str(), fourcc,
                pix.width, pix.height, pix.bytesperline, waited / 50.0);
    if (pix.pixelformat != V4L2_PIX_FMT_YUYV) {
        std::printf("vcam-check: expected YUYV\n");
        return 1;
    }
    const std::size_t frameBytes = static_cast<std::size_t>(pix.width) * pix.height * 2;

    v4l2_requestbuffers request{};
    request.count = 4;
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd, VIDIOC_REQBUFS, &request) != 0 || request.count == 0) {
        std::printf("vcam-check: VIDIOC_REQBUFS: %s\n", std::strerror(errno));
        return 1;
    }
    std::vector<std::pair<void*, std::size_t>> maps;
    for (std::uint32_t i = 0; i < request.count; ++i) {
        v4l2_buffer buffer{};
        buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buffer.memory = V4L2_MEMORY_MMAP;
        buffer.index = i;
        if (xioctl(fd, VIDIOC_QUERYBUF, &buffer) != 0)
            return std::printf("vcam-check: VIDIOC_QUERYBUF: %s\n", std::strerror(errno)), 1;
        void* at = ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, buffer.m.offset);
        if (at == MAP_FAILED)
            return std::printf("vcam-check: mmap: %s\n", std::strerror(errno)), 1;
        maps.emplace_back(at, buffer.length);
        if (xioctl(fd, VIDIOC_QBUF, &buffer) != 0)
            return std::printf("vcam-check: VIDIOC_QBUF: %s\n", std::strerror(errno)), 1;
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd, VIDIOC_STREAMON, &type) != 0)
        return std::printf("vcam-check: VIDIOC_STREAMON: %s\n", std::strerror(errno)), 1;

    // Capture until as many frames as references came, or the writer is done (DONE_FILE exists)
    // and nothing more comes, or nothing came for WAIT_S (under emulation a frame takes seconds).
    std::vector<std::vector<std::uint8_t>> frames;
    int idle = 0;
    while (frames.size() < refs.size()) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 200) <= 0) {
            std::error_code ec;
            if ((!doneFile.empty() && fs::exists(doneFile, ec)) || ++idle > waitS * 5)
                break;
            continue;
        }
        idle = 0;
        v4l2_buffer buffer{};
        buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buffer.memory = V4L2_MEMORY_MMAP;
        if (xioctl(fd, VIDIOC_DQBUF, &buffer) != 0) {
            if (errno == EAGAIN)
                continue;
            std::printf("vcam-check: VIDIOC_DQBUF: %s\n", std::strerror(errno));
            break;
        }
        if (buffer.bytesused < frameBytes) {
            std::printf("vcam-check: a frame of %u bytes, expected %zu\n", buffer.bytesused, frameBytes);
            return 1;
        }
        const auto* data = static_cast<const std::uint8_t*>(maps[buffer.index].first);
        frames.emplace_back(data, data + frameBytes);
        xioctl(fd, VIDIOC_QBUF, &buffer);
    }
    ::close(fd);

    // Each frame is matched to the reference it is closest to; those must be within the bound
    // and in order, and at most the first reference may be missing (written before the reader
    // streamed; v4l2loopback hands a late reader the newest frames).
    int status = 0;
    std::size_t next = 0;
    for (std::size_t k = 0; k < frames.size(); ++k) {
        double best = 1e9;
        std::size_t bestRef = 0;
        for (std::size_t r = 0; r < refs.size(); ++r) {
            const cv::Mat bgr = cv::imread(refs[r].string(), cv::IMREAD_COLOR);
            if (bgr.cols != static_cast<int>(pix.width) || bgr.rows != static_cast<int>(pix.height)) {
                std::printf("vcam-check: %s is %dx%d, the camera %ux%u\n", refs[r].c_str(), bgr.cols, bgr.rows,
                            pix.width, pix.height);
                return 1;
            }
            const double e = worstError(frames[k], bgr, pairChroma);
            if (e < best)
                best = e, bestRef = r;
        }
        const bool ok = best <= bound && bestRef >= next;
        std::printf("vcam-check: frame %zu = %s, largest difference %.3f codes (bound %.3f)%s\n", k,
                    refs[bestRef].filename().c_str(), best, bound, ok ? "" : "  FAIL");
        if (!ok)
            status = 1;
        next = bestRef + 1;
    }
    if (frames.size() + 1 < refs.size()) {
        std::printf("vcam-check: %zu frames captured of %zu written\n", frames.size(), refs.size());
        status = 1;
    }
    std::printf("vcam-check: %s\n", status == 0 ? "PASS" : "FAIL");
    return status;
}
