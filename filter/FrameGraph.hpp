// SPDX-License-Identifier: LGPL-2.1-or-later
// The passes of a frame, declared before any of them runs: an ordered list of nodes, each with
// its name (the GPU timer scope, the GL label, the rows of --timing), the images it reads and the
// images it writes. Depth preparation and the scene measurement come first (on the GPU; where
// they run on the CPU the filled depth is uploaded instead); the frame plan, made from the
// measurement, then picks the list (the rhombi or McIntosh's blurs, full or half
// size, the near field, the bokeh sprites); a view adds the nodes that make it from what the
// frame's nodes wrote. Pipeline runs the nodes in order and takes each image a node writes from
// a pool of targets keyed by format and size, so an image nobody's list names is never made.
// The graph is data: tests hold it valid (every image a node reads is one the frame imports or
// written by an earlier node; on the composite, every image written is read) without a GL context.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "defocus/Frame.hpp"
#include "filter/Settings.hpp"

namespace defocus {

/// The images (and one buffer) the passes of a frame read and write.
enum class Image : std::uint8_t {
    Color,          ///< the frame's colour, linear (imported: uploaded before the graph runs)
    ColorPlanes,    ///< the frame's colour as Y'CbCr planes (imported where they go up as they came)
    DepthAsGiven,   ///< the frame's depth as it came (imported where depth prep runs on the GPU)
    Depth,          ///< the frame's filled depth, the frame's size (depth prep's, or imported)
    Measurement,    ///< the scene measurement, a buffer the CPU reads back to plan the frame
    NearDiameter,   ///< the near field's diameter per tile (imported: uploaded from the analysis)
    Coc,            ///< colour and signed CoC at the blur size (View::Input)
    Sprites,        ///< the bokeh sprites found for the lights (a buffer)
    Horizontal,     ///< McIntosh's first blur, or the rhombi's line X (View::Horizontal)
    HorizontalMean, ///< the rhombi's line Z
    DiagonalA,      ///< McIntosh's or the rhombi's diagonal A (View::DiagonalA)
    DiagonalB,      ///< (View::DiagonalB)
    NearHorizontal, ///< McIntosh's near field, its first blur
    NearA,          ///< McIntosh's near field, diagonal A
    NearB,          ///< McIntosh's near field, diagonal B
    Blurred,        ///< half size: the blurred result before the upscale
    Sharpened,      ///< half size: the result prefiltered for the upscale
    Added,          ///< half size: the result minus the input, prefiltered
    Output,         ///< the view's image at the frame's size: what a read returns
    CallerTexture,  ///< readInto(): a caller's texture
};
inline constexpr int kImageCount = static_cast<int>(Image::CallerTexture) + 1;

/// How big an image is.
enum class ImageScale : std::uint8_t {
    Frame, ///< the frame's pixels
    Blur,  ///< the blur passes' pixels: the frame's, or half of them (FramePlan::blurShift)
    Tiles, ///< one texel per analysis tile
    Given, ///< the source's own (the depth, resized by depth prep)
    None   ///< a buffer
};

/// What an image holds.
enum class ImageFormat : std::uint8_t {
    Work,   ///< the blur targets' RGBA (rgb linear, a the signed CoC): RGBA16F or RGBA32F, by the
            ///< frame's TargetFormat; the pipeline's pool holds these
    Color,  ///< the frame as it went up: sRGB8 (decoded to linear on fetch) or RGB32F
    Planes, ///< Y'CbCr as it came: R8UI and RG8UI (NV12), R8UI (I420) or RG8UI (YUYV) planes
    Given,  ///< the depth as it came: R16UI in its units, or R32F metres
    Metres, ///< R32F metres
    Measurement, ///< SceneMeasurePass's storage buffer
    Pixels, ///< R32F, pixels of the blur
    Sprites, ///< a storage buffer of bokeh sprites
    Output, ///< what a read returns: sRGB8 with alpha, or RGBA32F for linear reads
    Rgba8,  ///< a caller's RGBA8 texture
};

struct ImageInfo {
    std::string_view name; ///< the GL label of its target
    ImageScale scale;
    ImageFormat format;
    /// A target of the pipeline's pool (ImageFormat::Work).
    bool pooled() const { return format == ImageFormat::Work; }
};
const ImageInfo& imageInfo(Image image);

/// What a node runs; Pipeline has one way to run each.
enum class PassKind : std::uint8_t {
    YuvToRgb,         ///< Y'CbCr planes to the frame's colour
    DepthPrep,        ///< the depth resized to the frame and its holes filled
    SceneMeasure,     ///< the valid depths' range, the tiles' CoC ranges, the highlights
    Coc,              ///< the CoC pass, the bokeh sprites found first when the plan has them
    RhombiLines,      ///< rhombi pass 1: the lines X and Z
    RhombiDiagonals,  ///< rhombi pass 2 into A and B
    RhombiComposite,  ///< rhombi pass 2 with the composite in it, into its one output
    McIntoshBlur,     ///< one of McIntosh's directional blurs (Node::turn says which)
    NearBlur,         ///< one of McIntosh's near-field blurs (Node::turn says which)
    Composite,        ///< A and B (and McIntosh's near layer) combined
    Prefilter,        ///< half size: the result prefiltered for the upscale
    Upscale,          ///< half size: the result upscaled, the frame's detail put back
    HighlightSprites, ///< the bokeh sprites drawn over the output
    InFocusLight,     ///< the light held back from pixels in focus put back
    ViewImage,        ///< a view of an image (colour, the CoC or the depth with its scale)
    OutputCopy,       ///< the output copied into a caller's texture
};

/// One pass of the frame.
struct Node {
    PassKind pass;
    /// The GPU timer scope and the row of --timing; unique within a frame's list.
    std::string_view name;
    std::vector<Image> reads;
    std::vector<Image> writes;
    /// McIntoshBlur and NearBlur: the direction, in thirds of a turn from the first (0, 1, -1).
    int turn = 0;
    /// ViewImage: the view it draws (the depth and the CoC with their scales, others as colour).
    View view = View::Composite;
};

/// What the graph of a frame depends on: the plan's choices.
struct GraphChoices {
    HexagonKernel kernel = HexagonKernel::RhombiSum;
    bool half = false;       ///< the blurs at half size, upscaled (FramePlan::blurShift != 0)
    bool nearField = false;  ///< FramePlan::nearField
    bool sprites = false;    ///< FramePlan::highlightSprites
};

/// The images a frame has before any node runs (its uploads): the colour (its Y'CbCr planes
/// where it came so, `yuvColor`, and the GPU prepares it), the near field's diameters (uploaded
/// when the frame is planned), and the depth as it came where depth prep runs on the GPU
/// (`depthPrepOnGpu`), the filled depth where it ran on the CPU.
std::vector<Image> frameImports(bool depthPrepOnGpu, bool yuvColor = false);

/// The nodes that prepare a frame for its plan, before the frame's nodes: on the GPU, the colour
/// from its Y'CbCr planes where it came so (`yuvColor`), depth prep and the scene measurement
/// (`lightEdges`: depth prep reads the colour to put the lights' edges at their lights' depth);
/// none where they run on the CPU (which converts Y'CbCr itself).
std::vector<Node> prepareNodes(bool depthPrepOnGpu, bool lightEdges, bool yuvColor = false);

/// The nodes every frame that is not all in focus runs, whatever is read: the CoC and the blurs
/// as far as they go without knowing the view.
std::vector<Node> frameNodes(const GraphChoices& choices);

/// The nodes that make `view` into Image::Output after the frame's nodes and any views read
/// before it: `written` holds what those wrote (indexed by Image), which the list reuses (the
/// rhombi's A and B, once a view of them wrote them). `toCaller` ends the list with the copy
/// into the caller's texture. View::Input, Horizontal, DiagonalA and DiagonalB read the blur
/// targets the frame's nodes wrote; readTarget() runs the list up to (not including) its last
/// node for them.
std::vector<Node> viewNodes(const GraphChoices& choices, View view, const std::vector<bool>& written,
                            bool toCaller = false);

/// frameNodes() and then the composite's viewNodes(): what a frame read once as the composite
/// runs, in order.
std::vector<Node> compositeFrame(const GraphChoices& choices);

/// The image a view shows (Coc for View::Input, the depth for View::Depth, Output for the
/// composite).
Image viewedImage(View view);

/// Why `nodes` (a frame's list, after `imports` were made) is not a valid frame: an image read
/// before any node wrote it, an import written, a name given twice, or (`everyWriteRead`) an
/// image written that no later node reads and that is not the output or the measurement (which
/// the CPU reads). Empty when valid.
std::string graphError(const std::vector<Node>& nodes, bool everyWriteRead, const std::vector<Image>& imports);

/// "coc > rhombi-1 > rhombi-2 > ..." for logs and --explain.
std::string describe(const std::vector<Node>& nodes);

} // namespace defocus
