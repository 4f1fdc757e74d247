// SPDX-License-Identifier: LGPL-2.1-or-later
// Fuzzes decodeDepth(): any bytes give CV_32FC1 metres of the size the header states, or a
// SourceError that names the file; never a crash, a leak or an allocation past the pixel limit.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "fuzz/DecodeSupport.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    defocus::fuzz::setUpOpenCv();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace defocus;
    const std::span<const unsigned char> bytes(data, size);
    try {
        const cv::Mat depth = decodeDepth(bytes, 5000.0, "fuzz.png", fuzz::kMaxPixels);
        FUZZ_CHECK(depth.type() == CV_32FC1, "depth of type %s", cv::typeToString(depth.type()).c_str());
        fuzz::checkAgainstHeader(bytes, depth);
    } catch (const SourceError& e) {
        const std::string message = e.what();
        FUZZ_CHECK(message.rfind("cannot read depth image 'fuzz.png': ", 0) == 0, "message: %s", message.c_str());
    }
    return 0;
}
