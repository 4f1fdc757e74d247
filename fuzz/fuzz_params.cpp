// SPDX-License-Identifier: LGPL-2.1-or-later
// Fuzzes parameter validation with arbitrary doubles (NaN, infinities, denormals included) and
// ints: validate() without clamping changes nothing and names each bad parameter; clamping gives
// settings that validate cleanly; valid lens settings give finite CoC coefficients and a CoC
// within +-max-coc for every positive depth; view names round-trip.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "filter/Lens.hpp"
#include "filter/Settings.hpp"
#include "fuzz/FuzzSupport.hpp"

namespace {

using namespace defocus;

// Any bit pattern, or (one time in four) a value at an edge: zero, the smallest denormal, the
// infinities, NaN, the documented limits, and a focus of 1 m that near/far limits can straddle.
double anyDouble(FuzzedDataProvider& in)
{
    static const double edges[] = {0.0,
                                       -0.0,
                                       std::numeric_limits<double>::denorm_min(),
                                       std::numeric_limits<double>::infinity(),
                                       -std::numeric_limits<double>::infinity(),
                                       std::numeric_limits<double>::quiet_NaN(),
                                       std::numeric_limits<double>::max(),
                                       1.0,
                                       std::nextafter(1.0, 0.0),
                                       std::nextafter(1.0, 2.0),
                                       limits::kFocalLengthMm[1],
                                       limits::kFNumber[0],
                                       limits::kFNumber[1],
                                       limits::kMaxCocPx[1],
                                       limits::kSensorWidthMm[0],
                                       limits::kFocalLengthMm[0] * 1e-3};
    const std::uint8_t pick = in.ConsumeIntegral<std::uint8_t>();
    if (pick < std::size(edges))
        return edges[pick];
    if (pick < 64)
        return edges[pick % std::size(edges)] * (1.0 + (pick - 32) * 1e-3);
    const std::uint64_t bits = in.ConsumeIntegral<std::uint64_t>();
    double value = 0.0;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

bool sameBits(const LensSettings& a, const LensSettings& b)
{
    return a.model == b.model && std::memcmp(&a.focalLengthMm, &b.focalLengthMm, sizeof(double)) == 0 &&
           std::memcmp(&a.fNumber, &b.fNumber, sizeof(double)) == 0 &&
           std::memcmp(&a.focusM, &b.focusM, sizeof(double)) == 0 &&
           std::memcmp(&a.sensorWidthMm, &b.sensorWidthMm, sizeof(double)) == 0 &&
           std::memcmp(&a.maxCocPx, &b.maxCocPx, sizeof(double)) == 0 &&
           std::memcmp(&a.nearLimitM, &b.nearLimitM, sizeof(double)) == 0 &&
           std::memcmp(&a.farLimitM, &b.farLimitM, sizeof(double)) == 0;
}

std::string describe(const LensSettings& l)
{
    return "model " + std::to_string(static_cast<int>(l.model)) + " f " + std::to_string(l.focalLengthMm) + " N " +
           std::to_string(l.fNumber) + " focus " + std::to_string(l.focusM) + " sensor " +
           std::to_string(l.sensorWidthMm) + " maxcoc " + std::to_string(l.maxCocPx) + " near " +
           std::to_string(l.nearLimitM) + " far " + std::to_string(l.farLimitM);
}

void checkIssues(const std::vector<SettingIssue>& issues)
{
    for (const SettingIssue& issue : issues) {
        FUZZ_CHECK(issue.parameter.rfind("--", 0) == 0, "parameter '%s'", issue.parameter.c_str());
        FUZZ_CHECK(issue.message.rfind(issue.parameter + " ", 0) == 0, "message '%s' does not start with '%s'",
                   issue.message.c_str(), issue.parameter.c_str());
    }
}

void checkLens(LensSettings lens, int width, float depth)
{
    const LensSettings original = lens;
    const std::vector<SettingIssue> issues = validate(lens, false);
    FUZZ_CHECK(sameBits(lens, original), "validate without clamping changed %s", describe(original).c_str());
    checkIssues(issues);

    // Clamping may report fewer issues: later checks see the clamped earlier values.
    LensSettings clamped = lens;
    checkIssues(validate(clamped, true));
    const std::vector<SettingIssue> after = validate(clamped, false);
    FUZZ_CHECK(after.empty(), "clamping %s left '%s'", describe(original).c_str(),
               after.empty() ? "" : after.front().message.c_str());

    for (const LensSettings& valid : {clamped}) {
        const CocCoefficients k = cocCoefficients(valid, width);
        FUZZ_CHECK(std::isfinite(k.nearScale) && std::isfinite(k.nearOffset) && std::isfinite(k.farScale) &&
                       std::isfinite(k.farOffset) && std::isfinite(k.focusM),
                   "non-finite coefficients for %s at %d px", describe(valid).c_str(), width);
        if (depth > 0.0f && std::isfinite(depth)) {
            const float c = cocPixels(k, depth);
            FUZZ_CHECK(std::isfinite(c) && std::abs(c) <= k.maxCocPx, "CoC %g px at %g m for %s", c,
                       static_cast<double>(depth), describe(valid).c_str());
        }
    }
}

void checkQuality(int samples, bool wide, double highlightGain)
{
    QualitySettings quality;
    quality.samples = samples;
    quality.targetFormat = wide ? TargetFormat::Rgba32F : TargetFormat::Rgba16F;
    quality.highlightGain = highlightGain;
    const std::vector<SettingIssue> issues = validate(quality, false);
    FUZZ_CHECK(quality.samples == samples, "validate without clamping changed samples %d", samples);
    const bool samplesOk = samples >= limits::kSamples[0] && samples <= limits::kSamples[1];
    const bool gainOk = std::isfinite(highlightGain) && highlightGain >= limits::kHighlightGain[0] &&
                        highlightGain <= limits::kHighlightGain[1];
    FUZZ_CHECK(issues.size() == static_cast<std::size_t>(!samplesOk) + static_cast<std::size_t>(!gainOk),
               "samples %d, highlight gain %g: %zu issues", samples, highlightGain, issues.size());
    checkIssues(issues);
    validate(quality, true);
    FUZZ_CHECK(validate(quality, false).empty(), "clamping samples %d, gain %g gave %d, %g", samples, highlightGain,
               quality.samples, quality.highlightGain);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    FuzzedDataProvider in(data, size);
    LensSettings lens;
    lens.model = in.ConsumeBool() ? CocModel::FocalRange : CocModel::ThinLens;
    lens.focalLengthMm = anyDouble(in);
    lens.fNumber = anyDouble(in);
    lens.focusM = anyDouble(in);
    lens.sensorWidthMm = anyDouble(in);
    lens.maxCocPx = anyDouble(in);
    lens.nearLimitM = anyDouble(in);
    lens.farLimitM = anyDouble(in);
    const int width = in.ConsumeIntegralInRange<int>(1, 16384);
    float depth = 0.0f;
    const std::uint32_t depthBits = in.ConsumeIntegral<std::uint32_t>();
    std::memcpy(&depth, &depthBits, sizeof depth);
    checkLens(lens, width, depth);

    const int samples = in.ConsumeIntegral<int>();
    const bool wide = in.ConsumeBool();
    checkQuality(samples, wide, anyDouble(in));

    const std::string name = in.ConsumeRemainingBytesAsString();
    View view = View::Composite;
    if (parseView(name, view))
        FUZZ_CHECK(viewName(view) == name, "parseView('%s') gave '%s'", name.c_str(), std::string(viewName(view)).c_str());
    for (const View v : kAllViews) {
        View back = View::Input;
        FUZZ_CHECK(parseView(viewName(v), back) && back == v, "view %d does not round-trip", static_cast<int>(v));
    }
    HexagonKernel kernel = HexagonKernel::RhombiSum;
    if (parseKernel(name, kernel))
        FUZZ_CHECK(kernelName(kernel) == name, "parseKernel('%s') gave '%s'", name.c_str(),
                   std::string(kernelName(kernel)).c_str());
    for (const HexagonKernel k : {HexagonKernel::McIntoshMin, HexagonKernel::RhombiSum}) {
        HexagonKernel back = k == HexagonKernel::RhombiSum ? HexagonKernel::McIntoshMin : HexagonKernel::RhombiSum;
        FUZZ_CHECK(parseKernel(kernelName(k), back) && back == k, "kernel %d does not round-trip", static_cast<int>(k));
    }
    Resolution resolution = Resolution::Full;
    if (parseResolution(name, resolution))
        FUZZ_CHECK(resolutionName(resolution) == name, "parseResolution('%s') gave '%s'", name.c_str(),
                   std::string(resolutionName(resolution)).c_str());
    for (const Resolution r : {Resolution::Full, Resolution::Half}) {
        Resolution back = r == Resolution::Full ? Resolution::Half : Resolution::Full;
        FUZZ_CHECK(parseResolution(resolutionName(r), back) && back == r, "resolution %d does not round-trip",
                   static_cast<int>(r));
    }
    return 0;
}
