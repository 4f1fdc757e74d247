// SPDX-License-Identifier: LGPL-2.1-or-later
// Filters one colour image + its 16-bit depth with libdefocus and writes the result as a PNG.
//   defocus-consumer COLOR DEPTH DEPTH_SCALE FOCUS_M F_NUMBER PRESET OUT.png
#include <cstdio>
#include <cstdlib>
#include <string>

#include <defocus/defocus.hpp>
#include <opencv2/imgcodecs.hpp>

int main(int argc, char** argv)
{
    if (argc != 8) {
        std::fprintf(stderr, "usage: %s COLOR DEPTH DEPTH_SCALE FOCUS_M F_NUMBER fast|balanced|high OUT.png\n", argv[0]);
        return 2;
    }
    defocus::Settings settings;
    settings.depthScale = std::atof(argv[3]);
    settings.lens.focusM = std::atof(argv[4]);
    settings.lens.fNumber = std::atof(argv[5]);
    const std::string preset = argv[6];
    settings.quality.preset = preset == "fast" ? defocus::Quality::Preset::Fast
                              : preset == "high" ? defocus::Quality::Preset::High
                                                 : defocus::Quality::Preset::Balanced;
    try {
        defocus::Filter filter(settings);
        const cv::Mat out = filter.process(cv::imread(argv[1], cv::IMREAD_COLOR), cv::imread(argv[2], cv::IMREAD_UNCHANGED));
        if (!cv::imwrite(argv[7], out)) {
            std::fprintf(stderr, "defocus-consumer: cannot write '%s'\n", argv[7]);
            return 1;
        }
        std::printf("defocus %s on %s: %s\n", defocus::version().c_str(), filter.renderer().c_str(),
                    filter.lastFrame().plan.explain.c_str());
    } catch (const defocus::Error& error) {
        std::fprintf(stderr, "defocus-consumer: %s\n", error.what());
        return 1;
    }
    return 0;
}
