// SPDX-License-Identifier: LGPL-2.1-or-later
// Exact-coverage aperture-polygon scatter with per-pixel depth layering (see ReferenceScatter.hpp).
#include "bench/methods/ReferenceScatter.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <numbers>
#include <vector>

#include <opencv2/core/utility.hpp>

namespace defocus {

namespace {

constexpr int kBandRows = 8; ///< destination rows per parallel task

struct Point {
    double x, y;
};

/// The aperture polygon with circumradius 1 (image coordinates, y down) and its area.
struct Polygon {
    std::array<Point, 16> corners{};
    int count = 0;
    double area = 0.0; ///< at circumradius 1
    double top = 0.0, bottom = 0.0; ///< smallest and largest y

    explicit Polygon(const ScatterOptions& options)
    {
        CV_Assert(options.blades >= 3 && options.blades <= 16);
        count = options.blades;
        const double step = 2.0 * std::numbers::pi / count;
        // The first corner at 90 degrees (on top) when rotationDeg is 0.
        const double rotation = (90.0 + options.rotationDeg) * std::numbers::pi / 180.0;
        for (int i = 0; i < count; ++i) {
            const double angle = rotation + step * i; // counter-clockwise on screen: y goes up
            corners[static_cast<std::size_t>(i)] = {std::cos(angle), -std::sin(angle)};
            top = std::min(top, corners[static_cast<std::size_t>(i)].y);
            bottom = std::max(bottom, corners[static_cast<std::size_t>(i)].y);
        }
        area = 0.5 * count * std::sin(step);
    }

    /// The polygon's x-interval at height y (circumradius 1), y within [top, bottom].
    std::pair<double, double> span(double y) const
    {
        double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
        for (int i = 0; i < count; ++i) {
            const Point& p = corners[static_cast<std::size_t>(i)];
            const Point& q = corners[static_cast<std::size_t>((i + 1) % count)];
            if ((p.y - y) * (q.y - y) > 0.0)
                continue;
            const double x = p.y == q.y ? p.x : p.x + (y - p.y) / (q.y - p.y) * (q.x - p.x);
            const double x2 = p.y == q.y ? q.x : x;
            lo = std::min({lo, x, x2});
            hi = std::max({hi, x, x2});
        }
        return {lo, hi};
    }
};

/// Sutherland-Hodgman step: keeps the part of polygon `in` (n vertices) where
/// sign * (coordinate[axis] - bound) >= 0; returns the new vertex count.
int clip(const Point* in, int n, Point* out, int axis, double bound, double sign)
{
    const auto value = [&](const Point& p) { return sign * ((axis == 0 ? p.x : p.y) - bound); };
    int m = 0;
    for (int i = 0; i < n; ++i) {
        const Point& current = in[i];
        const Point& previous = in[(i + n - 1) % n];
        const double vc = value(current), vp = value(previous);
        if ((vc >= 0.0) != (vp >= 0.0)) {
            const double t = vp / (vp - vc);
            out[m++] = {previous.x + t * (current.x - previous.x), previous.y + t * (current.y - previous.y)};
        }
        if (vc >= 0.0)
            out[m++] = current;
    }
    return m;
}

/// Overlap of the polygon (circumradius r, centred at the origin) with [x0, x0+1] x [y0, y0+1].
double overlapAtOrigin(const Polygon& polygon, double r, double x0, double y0)
{
    std::array<Point, 24> a{}, b{};
    for (int i = 0; i < polygon.count; ++i)
        a[static_cast<std::size_t>(i)] = {r * polygon.corners[static_cast<std::size_t>(i)].x,
                                          r * polygon.corners[static_cast<std::size_t>(i)].y};
    int n = polygon.count;
    n = clip(a.data(), n, b.data(), 0, x0, 1.0);
    n = clip(b.data(), n, a.data(), 0, x0 + 1.0, -1.0);
    n = clip(a.data(), n, b.data(), 1, y0, 1.0);
    n = clip(b.data(), n, a.data(), 1, y0 + 1.0, -1.0);
    double twiceArea = 0.0;
    for (int i = 0; i < n; ++i) {
        const Point& p = a[static_cast<std::size_t>(i)];
        const Point& q = a[static_cast<std::size_t>((i + 1) % n)];
        twiceArea += p.x * q.y - q.x * p.y;
    }
    return std::abs(twiceArea) / 2.0;
}

/// One source pixel.
struct Source {
    int x, y;
    float radius; ///< circumradius, pixels
    float coc;    ///< signed CoC, the depth key
};

/// One source's share of one destination pixel of a band.
struct Fragment {
    int pixel;    ///< index within the band
    int source;   ///< index into the sources
    float weight; ///< overlap / hexagon area
};

/// Splats every source reaching rows [row0, row1) into `fragments`.
void splatBand(const Polygon& polygon, const std::vector<Source>& sources, const std::vector<std::size_t>& rowStart,
               int cols, int rows, int row0, int row1, int reachRows, std::vector<Fragment>& fragments)
{
    fragments.clear();
    const int first = std::max(0, row0 - reachRows), last = std::min(rows, row1 + reachRows);
    for (std::size_t i = rowStart[static_cast<std::size_t>(first)]; i < rowStart[static_cast<std::size_t>(last)]; ++i) {
        const Source& s = sources[i];
        const int source = static_cast<int>(i);
        if (s.radius <= 0.5f) { // the polygon fits inside its own pixel
            if (s.y >= row0 && s.y < row1)
                fragments.push_back({(s.y - row0) * cols + s.x, source, 1.0f});
            continue;
        }
        const double r = s.radius, area = polygon.area * r * r;
        const double cx = s.x + 0.5, cy = s.y + 0.5;
        const double top = polygon.top * r, bottom = polygon.bottom * r;
        const int py0 = std::max(row0, static_cast<int>(std::floor(cy + top)));
        const int py1 = std::min(row1, static_cast<int>(std::ceil(cy + bottom)));
        for (int py = py0; py < py1; ++py) {
            // The row's band relative to the centre, in units of the circumradius.
            const double v0 = (py - cy) / r, v1 = (py + 1.0 - cy) / r;
            const double c0 = std::max(v0, polygon.top), c1 = std::min(v1, polygon.bottom);
            if (c0 >= c1)
                continue;
            // Outer span: the polygon's x-range within the band (at the band's edges or at a
            // corner inside it). Inner span: where the band is covered from edge to edge; the
            // polygon is convex, so its left edge is at its rightmost, and its right edge at its
            // leftmost, at one end of the band.
            auto [outerLo, outerHi] = polygon.span(c0);
            const auto [lo1, hi1] = polygon.span(c1);
            outerLo = std::min(outerLo, lo1);
            outerHi = std::max(outerHi, hi1);
            for (int k = 0; k < polygon.count; ++k) {
                const Point& p = polygon.corners[static_cast<std::size_t>(k)];
                if (p.y > c0 && p.y < c1) {
                    outerLo = std::min(outerLo, p.x);
                    outerHi = std::max(outerHi, p.x);
                }
            }
            double innerLo = 1.0, innerHi = -1.0;
            if (v0 >= polygon.top && v1 <= polygon.bottom) {
                const auto [l0, h0] = polygon.span(v0);
                innerLo = std::max(l0, lo1);
                innerHi = std::min(h0, hi1);
            }
            const int px0 = std::max(0, static_cast<int>(std::floor(cx + outerLo * r)));
            const int px1 = std::min(cols, static_cast<int>(std::ceil(cx + outerHi * r)));
            for (int px = px0; px < px1; ++px) {
                const double u0 = px - cx;
                const double overlap = (u0 >= innerLo * r && u0 + 1.0 <= innerHi * r)
                                           ? 1.0
                                           : overlapAtOrigin(polygon, r, u0, py - cy);
                if (overlap > 0.0)
                    fragments.push_back({(py - row0) * cols + px, source, static_cast<float>(overlap / area)});
            }
        }
    }
}

} // namespace

double polygonSquareOverlap(const ScatterOptions& options, double cx, double cy, double radius, double x, double y)
{
    return overlapAtOrigin(Polygon(options), radius, x - cx, y - cy);
}

cv::Mat referenceScatter(const cv::Mat& linear, const cv::Mat& cocPx, const ScatterOptions& options)
{
    CV_Assert(linear.type() == CV_32FC3 && cocPx.type() == CV_32FC1 && linear.size() == cocPx.size());
    CV_Assert(options.layerGapPx > 0.0f);
    const int rows = linear.rows, cols = linear.cols;

    // Sources in raster order, with where each row starts, so a band finds its sources by row.
    std::vector<Source> sources;
    sources.reserve(linear.total());
    std::vector<std::size_t> rowStart(static_cast<std::size_t>(rows) + 1, 0);
    float largestRadius = 0.0f;
    for (int y = 0; y < rows; ++y) {
        rowStart[static_cast<std::size_t>(y)] = sources.size();
        const float* c = cocPx.ptr<float>(y);
        for (int x = 0; x < cols; ++x) {
            const float radius = std::abs(c[x]) / 2.0f;
            largestRadius = std::max(largestRadius, radius);
            sources.push_back({x, y, radius, c[x]});
        }
    }
    rowStart[static_cast<std::size_t>(rows)] = sources.size();
    const Polygon polygon(options);
    const int reachRows = static_cast<int>(std::ceil(largestRadius * std::max(-polygon.top, polygon.bottom))) + 1;

    cv::Mat out(rows, cols, CV_32FC3, cv::Scalar::all(0.0));
    const int bands = (rows + kBandRows - 1) / kBandRows;
    cv::parallel_for_(cv::Range(0, bands), [&](const cv::Range& range) {
        std::vector<Fragment> fragments, sorted;
        std::vector<int> offsets;
        for (int band = range.start; band < range.end; ++band) {
            const int row0 = band * kBandRows, row1 = std::min(rows, row0 + kBandRows);
            splatBand(polygon, sources, rowStart, cols, rows, row0, row1, reachRows, fragments);

            // Bucket the fragments by destination pixel (counting sort).
            const int pixels = (row1 - row0) * cols;
            offsets.assign(static_cast<std::size_t>(pixels) + 1, 0);
            for (const Fragment& f : fragments)
                ++offsets[static_cast<std::size_t>(f.pixel) + 1];
            for (int p = 0; p < pixels; ++p)
                offsets[static_cast<std::size_t>(p) + 1] += offsets[static_cast<std::size_t>(p)];
            sorted.resize(fragments.size());
            {
                std::vector<int> next(offsets.begin(), offsets.end() - 1);
                for (const Fragment& f : fragments)
                    sorted[static_cast<std::size_t>(next[static_cast<std::size_t>(f.pixel)]++)] = f;
            }

            for (int p = 0; p < pixels; ++p) {
                const auto begin = sorted.begin() + offsets[static_cast<std::size_t>(p)];
                const auto end = sorted.begin() + offsets[static_cast<std::size_t>(p) + 1];
                // Far to near; ties by source index so that the result does not depend on order.
                std::sort(begin, end, [&](const Fragment& a, const Fragment& b) {
                    const float ca = sources[static_cast<std::size_t>(a.source)].coc;
                    const float cb = sources[static_cast<std::size_t>(b.source)].coc;
                    return ca != cb ? ca > cb : a.source < b.source;
                });
                double color[3] = {0.0, 0.0, 0.0}, alpha = 0.0;
                for (auto layerBegin = begin; layerBegin != end;) {
                    double layer[3] = {0.0, 0.0, 0.0}, coverage = 0.0;
                    auto it = layerBegin;
                    float previousCoc = sources[static_cast<std::size_t>(it->source)].coc;
                    for (; it != end; ++it) {
                        const Source& s = sources[static_cast<std::size_t>(it->source)];
                        if (previousCoc - s.coc > options.layerGapPx)
                            break;
                        previousCoc = s.coc;
                        const float* c = linear.ptr<float>(s.y) + 3 * s.x;
                        for (int k = 0; k < 3; ++k)
                            layer[k] += static_cast<double>(it->weight) * c[k];
                        coverage += it->weight;
                    }
                    if (coverage > 1.0) {
                        for (double& v : layer)
                            v /= coverage;
                        coverage = 1.0;
                    }
                    for (int k = 0; k < 3; ++k)
                        color[k] = layer[k] + (1.0 - coverage) * color[k];
                    alpha = coverage + (1.0 - coverage) * alpha;
                    layerBegin = it;
                }
                float* o = out.ptr<float>(row0 + p / cols) + 3 * (p % cols);
                if (alpha > 0.0)
                    for (int k = 0; k < 3; ++k)
                        o[k] = static_cast<float>(color[k] / alpha);
            }
        }
    });
    return out;
}

} // namespace defocus
