// SPDX-License-Identifier: LGPL-2.1-or-later
#include "filter/FrameGraph.hpp"

#include <array>
#include <set>
#include <string>

#include <fmt/format.h>

namespace defocus {

namespace {

using enum Image;

using F = ImageFormat;
constexpr std::array<ImageInfo, kImageCount> kImages{{
    {"input colour", ImageScale::Frame, F::Color},
    {"input colour planes", ImageScale::Given, F::Planes},
    {"depth as given", ImageScale::Given, F::Given},
    {"filled depth", ImageScale::Frame, F::Metres},
    {"scene measurement", ImageScale::None, F::Measurement},
    {"near diameter per tile", ImageScale::Tiles, F::Pixels},
    {"coc", ImageScale::Blur, F::Work},
    {"bokeh sprites", ImageScale::None, F::Sprites},
    {"horizontal / rhombi X", ImageScale::Blur, F::Work},
    {"rhombi Z", ImageScale::Blur, F::Work},
    {"diagonal A", ImageScale::Blur, F::Work},
    {"diagonal B", ImageScale::Blur, F::Work},
    {"near horizontal", ImageScale::Blur, F::Work},
    {"near A", ImageScale::Blur, F::Work},
    {"near B", ImageScale::Blur, F::Work},
    {"half-size result", ImageScale::Blur, F::Work},
    {"half-size result, sharpened", ImageScale::Blur, F::Work},
    {"half-size result minus input", ImageScale::Blur, F::Work},
    {"output", ImageScale::Frame, F::Output},
    {"caller's texture", ImageScale::Frame, F::Rgba8},
}};

/// `images`, with `extra` appended where `when` holds.
std::vector<Image> with(std::initializer_list<Image> images, bool when, Image extra)
{
    std::vector<Image> all(images);
    if (when)
        all.push_back(extra);
    return all;
}

bool isWritten(const std::vector<bool>& written, Image image)
{
    const auto index = static_cast<std::size_t>(image);
    return index < written.size() && written[index];
}

} // namespace

const ImageInfo& imageInfo(Image image)
{
    return kImages[static_cast<std::size_t>(image)];
}

std::vector<Image> frameImports(bool depthPrepOnGpu, bool yuvColor)
{
    return {depthPrepOnGpu && yuvColor ? ColorPlanes : Color, depthPrepOnGpu ? DepthAsGiven : Depth, NearDiameter};
}

std::vector<Node> prepareNodes(bool depthPrepOnGpu, bool lightEdges, bool yuvColor)
{
    if (!depthPrepOnGpu)
        return {};
    std::vector<Node> nodes;
    if (yuvColor)
        nodes.push_back({PassKind::YuvToRgb, "yuv-to-rgb", {ColorPlanes}, {Color}});
    nodes.push_back({PassKind::DepthPrep, "depth-prep", with({DepthAsGiven}, lightEdges, Color), {Depth}});
    nodes.push_back({PassKind::SceneMeasure, "scene-measure", {Depth, Color}, {Measurement}});
    return nodes;
}

std::vector<Node> frameNodes(const GraphChoices& c)
{
    std::vector<Node> nodes;
    // The sprites are found in the CoC pass's scope: it leaves their light out of the gather.
    nodes.push_back({PassKind::Coc, "coc", {Color, Depth}, with({Coc}, c.sprites, Sprites)});
    if (c.kernel == HexagonKernel::RhombiSum) {
        // Pass 2 waits for the view: the composite runs fused into it.
        nodes.push_back({PassKind::RhombiLines, "rhombi-1", with({Coc}, c.nearField, NearDiameter),
                         {Horizontal, HorizontalMean}});
        return nodes;
    }
    nodes.push_back({PassKind::McIntoshBlur, "horizontal", {Coc}, {Horizontal}, 0});
    nodes.push_back({PassKind::McIntoshBlur, "diagonal-a", {Horizontal}, {DiagonalA}, 1});
    nodes.push_back({PassKind::McIntoshBlur, "diagonal-b", {Horizontal}, {DiagonalB}, -1});
    if (c.nearField) {
        nodes.push_back({PassKind::NearBlur, "near-horizontal", {Coc, NearDiameter}, {NearHorizontal}, 0});
        nodes.push_back({PassKind::NearBlur, "near-diagonal-a", {NearHorizontal, NearDiameter}, {NearA}, 1});
        nodes.push_back({PassKind::NearBlur, "near-diagonal-b", {NearHorizontal, NearDiameter}, {NearB}, -1});
    }
    return nodes;
}

Image viewedImage(View view)
{
    switch (view) {
    case View::Input: return Coc;
    case View::Horizontal: return Horizontal;
    case View::DiagonalA: return DiagonalA;
    case View::DiagonalB: return DiagonalB;
    case View::Depth: return Depth;
    case View::Coc: return Coc;
    case View::Composite: return Output;
    }
    return Output;
}

std::vector<Node> viewNodes(const GraphChoices& c, View view, const std::vector<bool>& written, bool toCaller)
{
    std::vector<Node> nodes;
    const bool rhombi = c.kernel == HexagonKernel::RhombiSum;
    // The rhombi's A and B exist once a view of them (or readTarget()) ran pass 2 unfused.
    const bool diagonalsWritten = !rhombi || isWritten(written, DiagonalA);
    const Node rhombiDiagonals{PassKind::RhombiDiagonals, "rhombi-2",
                               with({Horizontal, HorizontalMean}, c.nearField, NearDiameter), {DiagonalA, DiagonalB}};
    if (view == View::Composite) {
        const Image blurred = c.half ? Blurred : Output;
        if (!diagonalsWritten) {
            nodes.push_back({PassKind::RhombiComposite, "rhombi-2",
                             with({Horizontal, HorizontalMean}, c.nearField, NearDiameter), {blurred}});
        } else {
            std::vector<Image> reads{DiagonalA, DiagonalB};
            if (!rhombi && c.nearField)
                reads.insert(reads.end(), {NearA, NearB});
            nodes.push_back({PassKind::Composite, "composite", reads, {blurred}});
        }
        if (c.half) {
            nodes.push_back({PassKind::Prefilter, "prefilter", {Blurred}, {Sharpened, Added}});
            nodes.push_back(
                {PassKind::Upscale, "upscale", {Color, Depth, Coc, Blurred, Sharpened, Added}, {Output}});
        }
        if (c.sprites) {
            // The lights' sprites over the output, then the light the CoC pass held back from the
            // pixels in focus (sprites never run with McIntosh's blurs or at quarter size).
            nodes.push_back({PassKind::HighlightSprites, "highlights", {Sprites, Depth, Output}, {Output}});
            nodes.push_back({PassKind::InFocusLight, "lights-in-focus",
                             with({Color, Depth, Coc, Output}, c.nearField, NearDiameter), {Output}});
        }
    } else {
        if ((view == View::DiagonalA || view == View::DiagonalB) && !diagonalsWritten)
            nodes.push_back(rhombiDiagonals);
        nodes.push_back({PassKind::ViewImage, "view", {viewedImage(view)}, {Output}, 0, view});
    }
    if (toCaller)
        nodes.push_back({PassKind::OutputCopy, "output-copy", {Output}, {CallerTexture}});
    return nodes;
}

std::vector<Node> compositeFrame(const GraphChoices& choices)
{
    std::vector<Node> nodes = frameNodes(choices);
    std::vector<bool> written(kImageCount, false);
    for (const Node& node : nodes)
        for (const Image image : node.writes)
            written[static_cast<std::size_t>(image)] = true;
    const std::vector<Node> view = viewNodes(choices, View::Composite, written);
    nodes.insert(nodes.end(), view.begin(), view.end());
    return nodes;
}

std::string graphError(const std::vector<Node>& nodes, bool everyWriteRead, const std::vector<Image>& imports)
{
    std::vector<bool> written(kImageCount, false), imported(kImageCount, false);
    for (const Image image : imports)
        written[static_cast<std::size_t>(image)] = imported[static_cast<std::size_t>(image)] = true;
    std::set<std::string_view> names;
    for (std::size_t n = 0; n < nodes.size(); ++n) {
        const Node& node = nodes[n];
        if (!names.insert(node.name).second)
            return fmt::format("node {} ({}): a second node of that name", n, node.name);
        for (const Image image : node.reads)
            if (!written[static_cast<std::size_t>(image)])
                return fmt::format("node {} ({}) reads {} before any node wrote it", n, node.name,
                                   imageInfo(image).name);
        for (const Image image : node.writes) {
            if (imported[static_cast<std::size_t>(image)])
                return fmt::format("node {} ({}) writes {}, which the frame imports", n, node.name,
                                   imageInfo(image).name);
            written[static_cast<std::size_t>(image)] = true;
        }
        if (!everyWriteRead)
            continue;
        for (const Image image : node.writes) {
            if (image == Output || image == CallerTexture || image == Measurement)
                continue;
            bool read = false;
            for (std::size_t later = n + 1; later < nodes.size() && !read; ++later)
                for (const Image input : nodes[later].reads)
                    read = read || input == image;
            if (!read)
                return fmt::format("node {} ({}) writes {}, which no later node reads", n, node.name,
                                   imageInfo(image).name);
        }
    }
    return {};
}

std::string describe(const std::vector<Node>& nodes)
{
    std::string text;
    for (const Node& node : nodes) {
        if (!text.empty())
            text += " > ";
        text += node.name;
    }
    return text;
}

} // namespace defocus
