// SPDX-License-Identifier: LGPL-2.1-or-later
// scene.json of an accuracy scene folder: parsing with one clear error per bad field, and the
// scene's images read as the benchmark measures them (linear colour and truth, depth in metres).
#include "sources/AccuracyScene.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "filter/ColorSpace.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"

namespace defocus {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

[[noreturn]] void fail(const fs::path& file, const std::string& what)
{
    throw SourceError(fmt::format("{}: {}", file.string(), what));
}

const Json& field(const Json& object, const char* name, const char* path, const fs::path& file)
{
    const auto it = object.find(name);
    if (it == object.end())
        fail(file, fmt::format("missing field '{}'", path));
    return *it;
}

double number(const Json& object, const char* name, const char* path, const fs::path& file)
{
    const Json& value = field(object, name, path, file);
    if (!value.is_number())
        fail(file, fmt::format("'{}' must be a number, got {}", path, value.dump()));
    const double x = value.get<double>();
    if (!std::isfinite(x))
        fail(file, fmt::format("'{}' must be finite", path));
    return x;
}

std::string text(const Json& object, const char* name, const char* path, const fs::path& file)
{
    const Json& value = field(object, name, path, file);
    if (!value.is_string() || value.get<std::string>().empty())
        fail(file, fmt::format("'{}' must be a non-empty string, got {}", path, value.dump()));
    return value.get<std::string>();
}

} // namespace

AccuracyScene parseAccuracyScene(std::string_view jsonText, const fs::path& dir)
{
    const fs::path file = dir / "scene.json";
    Json json;
    try {
        json = Json::parse(jsonText);
    } catch (const Json::parse_error& error) {
        fail(file, fmt::format("not JSON ({})", error.what()));
    }
    if (!json.is_object())
        fail(file, "expected a JSON object");

    AccuracyScene scene;
    scene.dir = dir;
    scene.name = dir.filename().string();
    if (scene.name.empty() || scene.name == ".")
        scene.name = fs::absolute(dir).lexically_normal().parent_path().filename().string();
    if (const auto it = json.find("description"); it != json.end() && it->is_string())
        scene.description = it->get<std::string>();
    scene.color = dir / text(json, "color", "color", file);
    scene.depth = dir / text(json, "depth", "depth", file);
    scene.truth = dir / text(json, "truth", "truth", file);
    if (json.contains("depthUnitsPerMetre")) {
        scene.depthUnitsPerMetre = number(json, "depthUnitsPerMetre", "depthUnitsPerMetre", file);
        if (scene.depthUnitsPerMetre <= 0.0)
            fail(file, fmt::format("'depthUnitsPerMetre' must be positive, got {}", scene.depthUnitsPerMetre));
    }

    const Json& lensJson = field(json, "lens", "lens", file);
    if (!lensJson.is_object())
        fail(file, "'lens' must be an object");
    LensSettings& lens = scene.lens;
    lens.model = CocModel::ThinLens;
    lens.focalLengthMm = number(lensJson, "focalLengthMm", "lens.focalLengthMm", file);
    lens.sensorWidthMm = number(lensJson, "sensorWidthMm", "lens.sensorWidthMm", file);
    lens.fNumber = number(lensJson, "fNumber", "lens.fNumber", file);
    lens.focusM = number(lensJson, "focusM", "lens.focusM", file);
    const double blades = number(lensJson, "blades", "lens.blades", file);
    if (blades != std::floor(blades) || !(blades >= 0.0 && blades <= 1000.0))
        fail(file, fmt::format("'lens.blades' is {}; expected a whole number (0 = circular)", blades));
    lens.blades = static_cast<int>(blades);
    lens.bladeRotationDeg = number(lensJson, "bladeRotationDeg", "lens.bladeRotationDeg", file);
    if (lensJson.contains("apertureRatio"))
        lens.apertureRatio = number(lensJson, "apertureRatio", "lens.apertureRatio", file);
    const std::string fov = text(lensJson, "fieldOfView", "lens.fieldOfView", file);
    if (!parseFieldOfView(fov, lens.fieldOfView))
        fail(file, fmt::format("'lens.fieldOfView' is '{}'; expected 'focal-length' (Blender, engines) or "
                               "'image-distance' (a real camera)",
                               fov));
    // The filter's own ranges, with the scene.json names instead of the CLI's.
    const std::pair<const char*, const char*> names[] = {{"--focal-length", "lens.focalLengthMm"},
                                                         {"--f-number", "lens.fNumber"},
                                                         {"--sensor-width", "lens.sensorWidthMm"},
                                                         {"--focus", "lens.focusM"},
                                                         {"--blades", "lens.blades"},
                                                         {"--blade-rotation", "lens.bladeRotationDeg"},
                                                         {"--aperture-ratio", "lens.apertureRatio"}};
    for (const SettingIssue& issue : validate(lens)) {
        std::string parameter = issue.parameter;
        for (const auto& [cli, jsonName] : names)
            if (issue.parameter == cli)
                parameter = jsonName;
        fail(file, fmt::format("'{}': {}", parameter, issue.message));
    }

    scene.truthEstimatedPsnrDb = std::nan("");
    if (const auto render = json.find("render"); render != json.end() && render->is_object())
        if (const auto db = render->find("truthEstimatedPsnrDb"); db != render->end() && db->is_number())
            scene.truthEstimatedPsnrDb = db->get<double>();
    return scene;
}

AccuracyScene loadAccuracyScene(const fs::path& dir)
{
    const fs::path file = dir / "scene.json";
    std::ifstream in(file);
    if (!in)
        throw SourceError(fmt::format("{}: cannot read (a scene folder holds scene.json)", file.string()));
    std::stringstream text;
    text << in.rdbuf();
    AccuracyScene scene = parseAccuracyScene(text.str(), dir);
    for (const fs::path* image : {&scene.color, &scene.depth, &scene.truth}) {
        std::error_code ec;
        if (!fs::is_regular_file(*image, ec))
            fail(file, fmt::format("names '{}', which does not exist", image->string()));
    }
    return scene;
}

std::vector<fs::path> findAccuracyScenes(const fs::path& path)
{
    std::error_code ec;
    if (!fs::is_directory(path, ec))
        throw SourceError(fmt::format("{}: not a folder (a scene folder or a folder of them)", path.string()));
    if (fs::is_regular_file(path / "scene.json", ec))
        return {path};
    std::vector<fs::path> scenes;
    for (const fs::directory_entry& entry : fs::directory_iterator(path, ec))
        if (entry.is_directory(ec) && fs::is_regular_file(entry.path() / "scene.json", ec))
            scenes.push_back(entry.path());
    if (scenes.empty())
        throw SourceError(
            fmt::format("{}: holds no scene.json, and no subfolder does (expected a scene folder or a corpus)",
                        path.string()));
    std::sort(scenes.begin(), scenes.end());
    return scenes;
}

AccuracyImages readAccuracyImages(const AccuracyScene& scene)
{
    const auto linear = [](const fs::path& file) {
        cv::Mat image = readColor(file);
        return image.depth() == CV_8U ? decodeSrgb(image) : image;
    };
    AccuracyImages images{linear(scene.color), readDepth(scene.depth, scene.depthUnitsPerMetre),
                          linear(scene.truth)};
    if (images.truth.size() != images.color.size())
        throw SourceError(fmt::format("{}: {}x{}, but the colour {} is {}x{}", scene.truth.string(),
                                      images.truth.cols, images.truth.rows, scene.color.string(), images.color.cols,
                                      images.color.rows));
    if (images.depth.size() != images.color.size())
        throw SourceError(fmt::format("{}: {}x{}, but the colour {} is {}x{}", scene.depth.string(),
                                      images.depth.cols, images.depth.rows, scene.color.string(), images.color.cols,
                                      images.color.rows));
    return images;
}

} // namespace defocus
