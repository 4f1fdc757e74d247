// SPDX-License-Identifier: LGPL-2.1-or-later
// scene.json of the accuracy corpus: the bundled scene read with its lens, and one clear error
// naming the file and the field for each kind of bad scene.json.
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "sources/AccuracyScene.hpp"
#include "sources/FrameSource.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

const char* kGood = R"({"color": "c.exr", "depth": "d.png", "truth": "t.exr",
  "lens": {"focalLengthMm": 50, "sensorWidthMm": 36, "fNumber": 1.8, "focusM": 1.2, "blades": 6,
           "bladeRotationDeg": 0, "fieldOfView": "focal-length"}})";

std::string replaced(std::string text, const std::string& from, const std::string& to)
{
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
}

/// The message of the SourceError parsing `json` throws, "" when it parses.
std::string errorOf(const std::string& json)
{
    try {
        parseAccuracyScene(json, "scenes/x");
    } catch (const SourceError& error) {
        return error.what();
    }
    return "";
}

// Defect caught: a loader that reads the wrong field or unit (the bundled scene's lens drives
// every corpus figure of the spheres scene).
TEST(AccuracyScene, BundledSpheresSceneHasItsLens)
{
    const AccuracyScene scene = loadAccuracyScene(fs::path(DEFOCUS_DATA_DIR) / "blender_spheres");
    EXPECT_EQ(scene.name, "blender_spheres");
    EXPECT_EQ(scene.lens.focalLengthMm, 85.0);
    EXPECT_EQ(scene.lens.fNumber, 1.4);
    EXPECT_EQ(scene.lens.focusM, 5.0);
    EXPECT_EQ(scene.lens.sensorWidthMm, 36.0);
    EXPECT_EQ(scene.lens.bladeRotationDeg, 0.0);
    EXPECT_EQ(scene.lens.fieldOfView, FieldOfView::FocalLength);
    EXPECT_EQ(scene.truth.filename(), "truth_f1.4_focus5_linear.exr");
    const AccuracyImages images = readAccuracyImages(scene);
    EXPECT_EQ(images.color.size(), cv::Size(640, 480));
    EXPECT_EQ(images.depth.type(), CV_32FC1);
}

// Defect caught: a bad scene.json that is accepted with a default (a missing f-number read as
// 2, a 2-bladed aperture, which no lens has, or a squeeze of 0) or rejected with a message that names neither
// the file nor the field.
TEST(AccuracyScene, EachBadFieldIsNamed)
{
    EXPECT_EQ(errorOf(kGood), "");
    const struct {
        std::string json, expected;
    } cases[] = {
        {"{not json", "scenes/x/scene.json: not JSON"},
        {"[1, 2]", "scenes/x/scene.json: expected a JSON object"},
        {replaced(kGood, R"("truth": "t.exr",)", ""), "scenes/x/scene.json: missing field 'truth'"},
        {replaced(kGood, R"("fNumber": 1.8,)", ""), "missing field 'lens.fNumber'"},
        {replaced(kGood, R"("fNumber": 1.8)", R"("fNumber": "1.8")"), "'lens.fNumber' must be a number"},
        {replaced(kGood, R"("fNumber": 1.8)", R"("fNumber": 0.5)"), "'lens.fNumber': --f-number must be between 0.7 and 64, not 0.5"},
        {replaced(kGood, R"("focusM": 1.2)", R"("focusM": 0.01)"), "'lens.focusM'"},
        {replaced(kGood, R"("blades": 6)", R"("blades": 2)"), "'lens.blades': --blades must be 0 (circular) or between 3 and 16, not 2"},
        {replaced(kGood, R"("blades": 6)", R"("blades": 5.5)"), "'lens.blades' is 5.5; expected a whole number"},
        {replaced(kGood, R"("blades": 6,)", R"("blades": 6, "apertureRatio": 0,)"), "'lens.apertureRatio': --aperture-ratio must be between 0.1 and 10, not 0"},
        {replaced(kGood, R"("focal-length")", R"("sensor")"), "'lens.fieldOfView' is 'sensor'"},
        {replaced(kGood, R"("color": "c.exr")", R"("color": "")"), "'color' must be a non-empty string"},
        {replaced(kGood, R"("truth": "t.exr",)", R"("truth": "t.exr", "depthUnitsPerMetre": -5,)"),
         "'depthUnitsPerMetre' must be positive"},
    };
    for (const auto& c : cases) {
        const std::string message = errorOf(c.json);
        EXPECT_NE(message.find(c.expected), std::string::npos) << "got: " << message << "\nexpected: " << c.expected;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

// Defect caught: a scene's aperture read as the default hexagon: a circular or 9-bladed, rotated,
// squeezed truth measured against hexagons.
TEST(AccuracyScene, ApertureIsTheTruths)
{
    std::string json = replaced(kGood, R"("blades": 6)", R"("blades": 9)");
    json = replaced(json, R"("bladeRotationDeg": 0)", R"("bladeRotationDeg": 15, "apertureRatio": 2)");
    const AccuracyScene scene = parseAccuracyScene(json, "scenes/x");
    EXPECT_EQ(scene.lens.blades, 9);
    EXPECT_EQ(scene.lens.bladeRotationDeg, 15.0);
    EXPECT_EQ(scene.lens.apertureRatio, 2.0);
    EXPECT_EQ(parseAccuracyScene(replaced(kGood, R"("blades": 6)", R"("blades": 0)"), "scenes/x").lens.blades, 0);
    EXPECT_EQ(parseAccuracyScene(kGood, "scenes/x").lens.apertureRatio, 1.0);
}

// Defect caught: a corpus folder whose scenes are not found (or found in another order), or
// an empty folder measured as an empty corpus instead of failing.
TEST(AccuracyScene, FindsSceneFoldersOfACorpus)
{
    const fs::path dir = fs::temp_directory_path() / fmt::format("defocus_corpus_{}", ::getpid());
    fs::remove_all(dir);
    fs::create_directories(dir / "b");
    fs::create_directories(dir / "a");
    fs::create_directories(dir / "not-a-scene");
    for (const char* name : {"a", "b"})
        std::ofstream(dir / name / "scene.json") << kGood;
    const auto scenes = findAccuracyScenes(dir);
    ASSERT_EQ(scenes.size(), 2u);
    EXPECT_EQ(scenes[0].filename(), "a");
    EXPECT_EQ(scenes[1].filename(), "b");
    EXPECT_EQ(findAccuracyScenes(dir / "a").size(), 1u);
    EXPECT_THROW(findAccuracyScenes(dir / "not-a-scene"), SourceError);
    EXPECT_THROW(findAccuracyScenes(dir / "missing"), SourceError);
    // A scene.json whose images are missing fails when loaded, naming the missing file.
    try {
        loadAccuracyScene(dir / "a");
        ADD_FAILURE() << "loaded a scene without its images";
    } catch (const SourceError& error) {
        EXPECT_NE(std::string(error.what()).find("c.exr"), std::string::npos) << error.what();
    }
    fs::remove_all(dir);
}

} // namespace
} // namespace defocus
