// SPDX-License-Identifier: LGPL-2.1-or-later
// Fuzzes decodeColor(): any bytes give 8-bit sRGB or float linear BGR of the size the header
// states, or a SourceError that names the file; never a crash, a leak or an allocation past the
// pixel limit. Colour decoded from 16-bit samples must lie in [0, 1].
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
        const cv::Mat color = decodeColor(bytes, "fuzz.png", fuzz::kMaxPixels);
        FUZZ_CHECK(color.type() == CV_8UC3 || color.type() == CV_32FC3, "colour of type %s",
                   cv::typeToString(color.type()).c_str());
        fuzz::checkAgainstHeader(bytes, color);
        if (color.type() == CV_32FC3 && readImageHeader(bytes).format != ImageFormat::OpenExr &&
            readImageHeader(bytes).format != ImageFormat::Tiff) {
            double low = 0.0, high = 0.0;
            cv::minMaxLoc(color.reshape(1), &low, &high);
            FUZZ_CHECK(low >= 0.0 && high <= 1.0, "16-bit colour decoded to [%g, %g]", low, high);
        }
    } catch (const SourceError& e) {
        const std::string message = e.what();
        FUZZ_CHECK(message.rfind("cannot read colour image 'fuzz.png': ", 0) == 0, "message: %s", message.c_str());
    }
    return 0;
}
