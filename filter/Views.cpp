// SPDX-License-Identifier: LGPL-2.1-or-later
// Legends and contact sheets, drawn with OpenCV.
#include "filter/Views.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "filter/ColorSpace.hpp"
#include "filter/SceneAnalysis.hpp"

namespace defocus {

namespace {

// The ramps of shaders/view.frag, in sRGB (R, G, B): keep the two in step.
cv::Vec3f depthRamp(float t)
{
    static const cv::Vec3f keys[5] = {{0.23f, 0.05f, 0.35f}, {0.20f, 0.30f, 0.60f}, {0.10f, 0.60f, 0.60f},
                                      {0.40f, 0.80f, 0.30f}, {0.99f, 0.91f, 0.15f}};
    const float s = std::clamp(t, 0.0f, 1.0f) * 4.0f;
    const int i = std::min(static_cast<int>(s), 3);
    const float f = s - static_cast<float>(i);
    return keys[i] * (1.0f - f) + keys[i + 1] * f;
}

cv::Vec3f cocRamp(float t)
{
    const cv::Vec3f white(1.0f, 1.0f, 1.0f), near(0.10f, 0.35f, 0.90f), far(0.90f, 0.25f, 0.10f);
    return t < 0.0f ? white * (1.0f + t) + near * (-t) : white * (1.0f - t) + far * t;
}

std::string label(LegendKind kind, float value)
{
    return kind == LegendKind::DepthMetres ? fmt::format("{:.2f} m", value) : fmt::format("{:+.0f} px", value);
}

} // namespace

void drawLegend(cv::Mat& image, LegendKind kind, float low, float high)
{
    if (image.cols < 160 || image.rows < 40)
        return;
    const bool linear = image.depth() == CV_32F;
    const auto toPixel = [linear](cv::Vec3f srgb) {
        // OpenCV images are BGR.
        if (linear)
            return cv::Scalar(srgbToLinear(srgb[2]), srgbToLinear(srgb[1]), srgbToLinear(srgb[0]));
        return cv::Scalar(srgb[2] * 255.0, srgb[1] * 255.0, srgb[0] * 255.0);
    };
    const double textScale = 0.4;
    const int barHeight = 10, margin = 6, textHeight = 14;
    const int top = image.rows - barHeight - textHeight - 2 * margin;
    cv::Mat region = image(cv::Rect(0, top, image.cols, image.rows - top));
    region *= 0.35; // darken behind the legend so its text stays readable
    const int barLeft = margin, barWidth = image.cols - 2 * margin;
    for (int x = 0; x < barWidth; ++x) {
        const float t = static_cast<float>(x) / static_cast<float>(barWidth - 1);
        const cv::Vec3f srgb = kind == LegendKind::DepthMetres ? depthRamp(t) : cocRamp(2.0f * t - 1.0f);
        cv::line(image, {barLeft + x, top + margin}, {barLeft + x, top + margin + barHeight}, toPixel(srgb));
    }
    const float middle = kind == LegendKind::DepthMetres ? std::sqrt(low * high) : 0.5f * (low + high);
    const cv::Scalar white = linear ? cv::Scalar(1, 1, 1) : cv::Scalar(255, 255, 255);
    const int baseline = image.rows - margin;
    const auto put = [&](const std::string& text, int x) {
        cv::putText(image, text, {x, baseline}, cv::FONT_HERSHEY_SIMPLEX, textScale, white, 1, cv::LINE_AA);
    };
    int unused = 0;
    const std::string right = label(kind, high), mid = label(kind, middle);
    put(label(kind, low), barLeft);
    put(mid, image.cols / 2 - cv::getTextSize(mid, cv::FONT_HERSHEY_SIMPLEX, textScale, 1, &unused).width / 2);
    put(right, image.cols - margin - cv::getTextSize(right, cv::FONT_HERSHEY_SIMPLEX, textScale, 1, &unused).width);
}

cv::Mat drawTileMap(const cv::Mat& image, const FramePlan& plan, const SceneAnalysis& analysis)
{
    CV_Assert(image.type() == CV_8UC3);
    cv::Mat map = image.clone();
    const int T = SceneAnalysis::kTileSize;
    const auto rect = [&](cv::Point tile) {
        return cv::Rect(tile.x * T, tile.y * T, T, T) & cv::Rect(0, 0, image.cols, image.rows);
    };
    for (const cv::Point tile : plan.copyTiles)
        map(rect(tile)) *= 0.4;
    for (const cv::Point tile : plan.nearTiles)
        map(rect(tile)) = map(rect(tile)) * 0.6 + cv::Scalar(255, 90, 0) * 0.4;
    for (const cv::Point tile : plan.blurTiles)
        cv::rectangle(map, rect(tile), cv::Scalar(0, 140, 255), 1);
    (void)analysis;
    return map;
}

cv::Mat contactSheet(const std::vector<std::pair<std::string, cv::Mat>>& tiles, int columns)
{
    CV_Assert(!tiles.empty() && columns > 0);
    const cv::Size tile = tiles.front().second.size();
    const int labelHeight = 24, gap = 4;
    const int count = static_cast<int>(tiles.size());
    const int cols = std::min(columns, count);
    const int rows = (count + cols - 1) / cols;
    cv::Mat sheet(rows * (tile.height + labelHeight + gap) + gap, cols * (tile.width + gap) + gap, CV_8UC3,
                  cv::Scalar(32, 32, 32));
    for (int i = 0; i < count; ++i) {
        const auto& [name, image] = tiles[static_cast<std::size_t>(i)];
        CV_Assert(image.type() == CV_8UC3 && image.size() == tile);
        const int x = gap + (i % cols) * (tile.width + gap);
        const int y = gap + (i / cols) * (tile.height + labelHeight + gap);
        cv::putText(sheet, name, {x + 2, y + labelHeight - 7}, cv::FONT_HERSHEY_SIMPLEX, 0.6,
                    cv::Scalar(240, 240, 240), 1, cv::LINE_AA);
        image.copyTo(sheet(cv::Rect(x, y + labelHeight, tile.width, tile.height)));
    }
    return sheet;
}

} // namespace defocus
