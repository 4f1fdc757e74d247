// SPDX-License-Identifier: LGPL-2.1-or-later
// Upscale pass: the CoC pass's lens parameters (the shader recomputes each pixel's CoC from the
// frame's depth) and a draw over the frame-sized target.
#include "filter/passes/UpscalePass.hpp"

#include <string>

#include <fmt/format.h>

#include "filter/SceneAnalysis.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {

std::vector<std::string> defines(int sizeShift, bool interpolateOnly)
{
    std::vector<std::string> list{fmt::format("DETAIL_BELOW_PX {:.6f}", upscaleDetailBelowPx(sizeShift)),
                                  fmt::format("BLUR_SCALE {:.6f}", 1.0 / (1 << sizeShift))};
    if (interpolateOnly)
        list.emplace_back("INTERPOLATE_ONLY 1");
    return list;
}

} // namespace

UpscalePass::Programs::Programs(int sizeShift)
    : full("fullscreen.vert", "upscale.frag", sizeShift == 1 ? kName : "upscale quarter",
           defines(sizeShift, false)),
      detailTiles("tiles.vert", "upscale.frag", sizeShift == 1 ? "upscale detail tiles" : "upscale quarter detail tiles",
                  defines(sizeShift, false)),
      interpolateOnly("fullscreen.vert", "upscale.frag",
                      sizeShift == 1 ? "upscale interpolate" : "upscale quarter interpolate", defines(sizeShift, true))
{
}

UpscalePass::UpscalePass()
    : half_(1),
      quarter_(2),
      prefilter_("fullscreen.vert", "upscale_prefilter.frag", "upscale prefilter"),
      nearest_(GL_NEAREST, "upscale nearest"),
      linear_(GL_LINEAR, "upscale linear")
{
}

void UpscalePass::prefilter(const Io& io)
{
    bindTexture(0, io.blurred.id(), nearest_.id());
    bindTexture(1, io.halfInput.id(), nearest_.id());
    shade(prefilter_, io.prefiltered);
}

void UpscalePass::upscale(const Io& io, const CocParams& params, int sizeShift, const TileList* detailTiles)
{
    Programs& programs = sizeShift == 2 ? quarter_ : half_;
    params.bind();
    bindTexture(0, io.color.id(), nearest_.id());
    bindTexture(1, io.depth.id(), nearest_.id());
    bindTexture(2, io.sharpened.id(), linear_.id());
    bindTexture(3, io.added.id(), linear_.id());
    if (!detailTiles) {
        shade(programs.full, io.target);
        return;
    }
    shade(programs.interpolateOnly, io.target);
    if (detailTiles->count() > 0)
        shade(programs.detailTiles, io.target, detailTiles);
}

} // namespace defocus
