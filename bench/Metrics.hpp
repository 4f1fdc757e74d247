// SPDX-License-Identifier: LGPL-2.1-or-later
// Error of a result against a ground truth (both CV_32FC3 linear BGR): PSNR of linear values
// clipped to [0, 1], PSNR after sRGB encoding, SSIM on luma, PSNR per region (in focus, out of
// focus, depth edge) with the regions drawn from the thin-lens CoC map, and PSNR and share of the
// squared error per zone (lights, depth edges, in focus, near, far). CPU only, no GL.
#pragma once

#include <array>
#include <string_view>

#include <opencv2/core.hpp>

#include "filter/Lens.hpp"

namespace defocus {

/// PSNR in dB from a mean squared error, for a peak value `peak`. MSE 0 gives +infinity: two
/// identical images have no finite PSNR, and no cap is applied (callers that print or store it
/// must handle inf; the accuracy benchmark writes it as null in JSON and "inf" in CSV).
double psnrFromMse(double mse, double peak = 1.0);

/// PSNR (peak 1) of `image` against `truth`, both CV_32FC3 linear, each value clipped to [0, 1]
/// first (NaN counts as 0), averaged over all three channels of the pixels where `mask`
/// (CV_8UC1, optional) is non-zero. +infinity when they agree exactly; NaN for an empty mask.
double psnrLinear(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& mask = {});

/// The same after encoding both with the sRGB transfer function (no 8-bit rounding), i.e. the
/// error as a display shows it.
double psnrSrgb(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& mask = {});

/// Luma Y' = 0.2126 R' + 0.7152 G' + 0.0722 B' of the sRGB-encoded, clipped colour (CV_32FC1 in
/// [0, 1]): what SSIM is computed on.
cv::Mat srgbLuma(const cv::Mat& linear);

/// Mean SSIM (Wang, Bovik, Sheikh & Simoncelli 2004) on luma: 11x11 Gaussian window, sigma 1.5,
/// K1 = 0.01, K2 = 0.03, dynamic range L = 1; the map is averaged over the pixels whose whole
/// window lies inside the image (the paper's 'valid' filtering), so a 5-pixel border is left
/// out. Exactly 1 for identical images.
double ssimLuma(const cv::Mat& image, const cv::Mat& truth);

/// The three regions errors are split into. Every pixel is in exactly one.
enum class Region : unsigned char {
    InFocus = 0,    ///< |CoC| < RegionOptions::inFocusCocPx and not near a depth edge
    OutOfFocus = 1, ///< |CoC| >= inFocusCocPx and not near a depth edge
    DepthEdge = 2   ///< within the blur radius of a depth edge (see regionMap())
};
inline constexpr std::array<Region, 3> kRegions{Region::InFocus, Region::OutOfFocus, Region::DepthEdge};
std::string_view regionName(Region region); ///< "in-focus", "out-of-focus", "depth-edge"

struct RegionOptions {
    /// A pixel whose thin-lens blur disc is narrower than this is in focus, pixels, > 0.
    float inFocusCocPx = 1.0f;
    /// Two 4-neighbours whose CoC differs by more than this sit on a depth edge, pixels, > 0.
    /// A smooth surface changes its CoC far more slowly (the Blender ground plane: about 0.2 px
    /// per row); an object boundary jumps by the difference of the two blurs.
    float edgeJumpPx = 1.0f;
    /// Added to the band's radius, pixels, >= 0: covers the half-pixel of sampling on each side.
    float edgeMarginPx = 1.0f;
};

/// Signed CoC diameter (pixels) of every pixel of `depthMetres` (CV_32FC1, no holes), exactly as
/// the CoC pass computes it (cocPixels()).
cv::Mat cocMap(const cv::Mat& depthMetres, const CocCoefficients& k);

/// Labels each pixel of a signed CoC map (CV_32FC1, pixels) with its Region (CV_8UC1):
/// 1. Depth edge: take every pair of 4-neighbours p, q with |c(p) - c(q)| > edgeJumpPx. Around
///    both p and q, mark the disc of radius r = max(|c(p)|, |c(q)|) / 2 + edgeMarginPx: the
///    larger of the two blur radii, which is as far as either side's light can cross the edge
///    in a thin-lens image (or as far as a gather filter can pull it across). The union of those
///    discs is the depth-edge region.
/// 2. Of the remaining pixels, |c| < inFocusCocPx is in focus, the rest out of focus.
cv::Mat regionMap(const cv::Mat& cocPx, const RegionOptions& options = {});

/// Every figure of one result against the truth.
struct ErrorReport {
    double psnrLinear = 0.0; ///< dB, whole image
    double psnrSrgb = 0.0;   ///< dB, whole image
    double ssim = 0.0;       ///< mean SSIM on luma
    std::array<double, 3> regionPsnr{};  ///< dB, linear clipped, per Region (NaN for an empty region)
    std::array<double, 3> regionShare{}; ///< share of the image's pixels in each Region
};

/// Measures `image` against `truth` (both CV_32FC3 linear, same size) with the region labels
/// `regions` from regionMap().
ErrorReport measureError(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& regions);

/// The zones the corpus report splits the error into, to say where it comes from. Every pixel is
/// in exactly one; the first that applies wins, in this order.
enum class Zone : unsigned char {
    Lights = 0,    ///< within ZoneOptions::lightRadiusPx of an input pixel brighter than white
    DepthEdge = 1, ///< Region::DepthEdge of regionMap()
    InFocus = 2,   ///< Region::InFocus
    Near = 3,      ///< out of focus in front of the focus (CoC < 0)
    Far = 4        ///< out of focus behind it (CoC > 0)
};
inline constexpr std::array<Zone, 5> kZones{Zone::Lights, Zone::DepthEdge, Zone::InFocus, Zone::Near, Zone::Far};
std::string_view zoneName(Zone zone); ///< "lights", "depth-edges", "in-focus", "near", "far"

struct ZoneOptions {
    /// An input pixel whose largest linear channel exceeds this is a light, > 0. Above white,
    /// a light's bokeh stays saturated where a filter spreads it too little, and spreads
    /// energy a clipped display would not show where it spreads it too much.
    float lightThreshold = 1.0f;
    /// Pixels within this distance of a light belong to the lights zone, pixels, >= 0: 30 px
    /// covers the bokeh of a light blurred up to a 60 px CoC.
    float lightRadiusPx = 30.0f;
    RegionOptions regions; ///< depth edges and focus, as regionMap()
};

/// Labels each pixel with its Zone (CV_8UC1) from the input colour (CV_32FC3 linear) and its
/// signed CoC map (CV_32FC1, pixels), the same size.
cv::Mat zoneMap(const cv::Mat& inputLinear, const cv::Mat& cocPx, const ZoneOptions& options = {});

/// Error per zone of one result.
struct ZoneReport {
    std::array<double, 5> psnr{};       ///< dB, linear clipped, per Zone (NaN for an empty zone)
    std::array<double, 5> share{};      ///< share of the pixels in each Zone
    std::array<double, 5> errorShare{}; ///< share of the whole image's squared error in each Zone
};

/// Measures `image` against `truth` (CV_32FC3 linear, same size) per zone of `zones` (zoneMap()).
ZoneReport measureZones(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& zones);

} // namespace defocus
