// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench accuracy on a scene folder, end to end: the bundled spheres scene read through
// its scene.json must reproduce the presets' recorded figures, and the zone report must account
// for every pixel and all of the error.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include "bench/methods/Presets.hpp"
#include "filter/Presets.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

// Defect caught: a scene loader that reads the lens, the depth's units, the truth or the colour's
// encoding wrongly (any of them moves the spheres scene's PSNR by far more than 0.02 dB: the
// presets' recorded figures came from the older, hard-wired loader), and a zone map that loses
// pixels or error (shares that do not add up to 1), or finds no lights in a scene full of them.
TEST(BenchAccuracy, SpheresSceneFolderReproducesThePresetsFigures)
{
    const fs::path out = test::scratchDir("bench_accuracy");
    const fs::path binary = fs::path(DEFOCUS_BINARY_DIR) / "defocus-bench-accuracy";
    ASSERT_TRUE(fs::exists(binary)) << binary << " is missing: build the 'defocus-bench-accuracy' target first";
    const std::string command = fmt::format("'{}' --scene '{}/blender_spheres' --presets balanced,high --output '{}' 2>&1",
                                            binary.string(), DEFOCUS_DATA_DIR, out.string());
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    for (char chunk[4096]; std::fgets(chunk, sizeof chunk, pipe);)
        output += chunk;
    const int status = ::pclose(pipe);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command << "\n" << output;

    std::ifstream file(out / "corpus.json");
    ASSERT_TRUE(file) << output;
    const nlohmann::json json = nlohmann::json::parse(file);
    ASSERT_EQ(json.at("scenes").size(), 1u);
    const nlohmann::json& scene = json.at("scenes").at(0);
    EXPECT_EQ(scene.at("scene"), "blender_spheres");
    int presetsSeen = 0;
    for (const nlohmann::json& row : scene.at("results")) {
        const std::string what = row.at("what");
        double pixels = 0.0, error = 0.0;
        for (const auto& [name, zone] : row.at("zones").items()) {
            pixels += zone.at("pixelShare").get<double>();
            error += zone.at("errorShare").get<double>();
        }
        EXPECT_NEAR(pixels, 1.0, 1e-6) << what;
        EXPECT_NEAR(error, 1.0, 1e-6) << what;
        // The scene's lights (up to 80) and their bokeh: a fifth of the frame lies within 30 px.
        EXPECT_GT(row.at("zones").at("lights").at("pixelShare").get<double>(), 0.05) << what;
        if (what == "input")
            continue;
        ++presetsSeen;
        EXPECT_NEAR(row.at("psnrLinearDb").get<double>(), preset(what).psnrDb, 0.02) << what;
    }
    EXPECT_EQ(presetsSeen, 2);
}

} // namespace
} // namespace defocus
