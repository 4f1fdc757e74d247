// SPDX-License-Identifier: LGPL-2.1-or-later
// The frame graph's lists, without a GL context: every list the plan can pick is a valid frame
// (an image is written before it is read; on the composite, nothing is written that nothing
// reads), and the lists name the passes the timings report.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "filter/FrameGraph.hpp"

namespace defocus {
namespace {

std::vector<GraphChoices> everyChoice()
{
    std::vector<GraphChoices> all;
    for (HexagonKernel kernel : {HexagonKernel::RhombiSum, HexagonKernel::McIntoshMin})
        for (bool half : {false, true})
            for (bool near : {false, true})
                for (bool sprites : {false, true})
                    all.push_back({kernel, half, near, sprites});
    return all;
}

std::string label(const GraphChoices& c)
{
    return std::string(c.kernel == HexagonKernel::RhombiSum ? "rhombi" : "mcintosh") + (c.half ? " half" : " full") +
           (c.nearField ? " near" : "") + (c.sprites ? " sprites" : "");
}

std::vector<bool> writtenBy(const std::vector<Node>& nodes)
{
    std::vector<bool> written(kImageCount, false);
    for (const Node& node : nodes)
        for (const Image image : node.writes)
            written[static_cast<std::size_t>(image)] = true;
    return written;
}

std::vector<Node> concat(std::vector<Node> first, const std::vector<Node>& second)
{
    first.insert(first.end(), second.begin(), second.end());
    return first;
}

// Catches a node that reads an image no earlier node wrote (a view that runs before the pass
// that makes its input, a list that forgets a pass, depth prep on the GPU left out) and, on the
// composite, a target written and never read (work the frame pays for and nobody sees); with
// depth prep on the GPU and on the CPU, the lights' edges put at their depth or not.
TEST(FrameGraph, EveryListIsAValidFrame)
{
    const View views[] = {View::Composite, View::Input, View::Horizontal, View::DiagonalA,
                          View::DiagonalB, View::Depth, View::Coc};
    for (const bool onGpu : {true, false})
        for (const bool lightEdges : {true, false})
            for (const bool yuv : {false, true})
            for (const GraphChoices& c : everyChoice()) {
                const std::vector<Node> frame = concat(prepareNodes(onGpu, lightEdges, yuv), frameNodes(c));
                for (const View view : views)
                    for (bool toCaller : {false, true}) {
                        const std::vector<Node> nodes = concat(frame, viewNodes(c, view, writtenBy(frame), toCaller));
                        // Views other than the composite show one image of the frame's and leave the rest.
                        EXPECT_EQ(graphError(nodes, view == View::Composite, frameImports(onGpu, yuv)), "")
                            << label(c) << (onGpu ? ", GPU" : ", CPU") << " depth prep" << (yuv ? ", Y'CbCr" : "")
                            << ", view " << static_cast<int>(view)
                            << ": " << describe(nodes);
                        EXPECT_EQ(nodes.back().writes.back(), toCaller ? Image::CallerTexture : Image::Output)
                            << label(c);
                    }
            }
}

// Catches a view read after another that runs the rhombi's second pass twice or skips it: after
// a view of A, the composite reads the A and B written, and a second view of B runs nothing new.
TEST(FrameGraph, LaterViewsReuseWhatEarlierViewsWrote)
{
    for (const GraphChoices& c : everyChoice()) {
        std::vector<Node> nodes = frameNodes(c);
        nodes = concat(nodes, viewNodes(c, View::DiagonalA, writtenBy(nodes)));
        const std::vector<Node> composite = viewNodes(c, View::Composite, writtenBy(nodes));
        const std::vector<Node> second = viewNodes(c, View::DiagonalB, writtenBy(nodes));
        EXPECT_EQ(second.size(), 1u) << label(c) << ": " << describe(second);
        EXPECT_EQ(composite.front().pass, PassKind::Composite) << label(c) << ": " << describe(composite);
        EXPECT_EQ(graphError(concat(nodes, composite), false, frameImports(false)), "")
            << label(c) << ": " << describe(composite);
    }
}

// Catches the graph checker passing what it exists to refuse.
TEST(FrameGraph, TheCheckRefusesAnInvalidFrame)
{
    const GraphChoices c{HexagonKernel::RhombiSum, true, true, true};
    std::vector<Node> nodes = concat(frameNodes(c), viewNodes(c, View::Composite, writtenBy(frameNodes(c))));
    // The upscale before the prefilter that makes its inputs.
    std::vector<Node> swapped = nodes;
    for (std::size_t i = 0; i + 1 < swapped.size(); ++i)
        if (swapped[i].pass == PassKind::Prefilter)
            std::swap(swapped[i], swapped[i + 1]);
    const std::vector<Image> imports = frameImports(false);
    EXPECT_NE(graphError(swapped, false, imports).find("reads"), std::string::npos) << describe(swapped);
    // A pass whose image nothing reads.
    std::vector<Node> unread = nodes;
    unread.insert(unread.begin() + 1, Node{PassKind::McIntoshBlur, "horizontal", {Image::Coc}, {Image::DiagonalA}});
    EXPECT_NE(graphError(unread, true, imports).find("no later node reads"), std::string::npos) << describe(unread);
    // Two scopes of one name.
    std::vector<Node> twice = nodes;
    twice.push_back(nodes.front());
    EXPECT_NE(graphError(twice, false, imports).find("second node"), std::string::npos);
    // The frame's nodes where depth prep runs on the GPU and the list leaves it out: the depth
    // the CoC pass reads was never filled.
    EXPECT_NE(graphError(nodes, false, frameImports(true)).find("reads filled depth"), std::string::npos);
    // A pass that draws over the frame's colour, which later passes read as it came.
    std::vector<Node> overwrite = nodes;
    overwrite.insert(overwrite.begin() + 1, Node{PassKind::Prefilter, "paint", {Image::Coc}, {Image::Color}});
    EXPECT_NE(graphError(overwrite, false, imports).find("which the frame imports"), std::string::npos);
}

// Catches depth prep and the measurement listed where they run on the CPU, or not where on the
// GPU, and depth prep not reading the colour it puts the lights' edges from.
TEST(FrameGraph, DepthPrepIsANodeWhereItRunsOnTheGpu)
{
    EXPECT_EQ(describe(prepareNodes(true, true)), "depth-prep > scene-measure");
    EXPECT_EQ(describe(prepareNodes(false, true)), "");
    // Y'CbCr colour: converted first on the GPU; on the CPU, before the upload.
    EXPECT_EQ(describe(prepareNodes(true, true, true)), "yuv-to-rgb > depth-prep > scene-measure");
    EXPECT_EQ(describe(prepareNodes(false, true, true)), "");
    const std::vector<Node> withEdges = prepareNodes(true, true), without = prepareNodes(true, false);
    EXPECT_EQ(withEdges.front().reads, (std::vector<Image>{Image::DepthAsGiven, Image::Color}));
    EXPECT_EQ(without.front().reads, std::vector<Image>{Image::DepthAsGiven});
}

// Catches a plan choice that does not reach the graph: each choice changes the passes run.
TEST(FrameGraph, ThePlanPicksTheList)
{
    const auto names = [](const GraphChoices& c) {
        return describe(concat(frameNodes(c), viewNodes(c, View::Composite, writtenBy(frameNodes(c)))));
    };
    EXPECT_EQ(names({HexagonKernel::RhombiSum, false, false, false}), "coc > rhombi-1 > rhombi-2");
    EXPECT_EQ(names({HexagonKernel::RhombiSum, true, true, true}),
              "coc > rhombi-1 > rhombi-2 > prefilter > upscale > highlights > lights-in-focus");
    EXPECT_EQ(names({HexagonKernel::McIntoshMin, false, false, false}),
              "coc > horizontal > diagonal-a > diagonal-b > composite");
    EXPECT_EQ(names({HexagonKernel::McIntoshMin, true, true, false}),
              "coc > horizontal > diagonal-a > diagonal-b > near-horizontal > near-diagonal-a > near-diagonal-b > "
              "composite > prefilter > upscale");
}

} // namespace
} // namespace defocus
