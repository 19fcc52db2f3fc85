#include "sim/material/curve.hpp"

#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viscera::sim {

namespace {

/// Derivative at nodes[i] of the polynomial interpolating (x_j, y_j), j in [lo, hi]:
/// Σ_{j≠i} L′_j(x_i) (y_j − y_i) (Σ_j L′_j = 0, so the differences avoid cancellation).
double lagrangeSlope(const std::vector<CurvePoint>& p, std::size_t lo, std::size_t hi, std::size_t i) {
    const double xi = p[i].x;
    double slope = 0;
    for (std::size_t j = lo; j <= hi; ++j) {
        if (j == i) continue;
        double numer = 1, denom = 1;
        for (std::size_t m = lo; m <= hi; ++m) {
            if (m == j) continue;
            denom *= p[j].x - p[m].x;
            if (m != i) numer *= xi - p[m].x;
        }
        slope += numer / denom * (p[j].y - p[i].y);
    }
    return slope;
}

} // namespace

MonotoneCurve::MonotoneCurve(std::string name, std::vector<CurvePoint> points, CurveShape shape, std::string context)
    : m_name(std::move(name)), m_context(std::move(context)), m_shape(shape), m_points(std::move(points)) {
    check(m_points);
    rebuild();
}

MonotoneCurve MonotoneCurve::fit(std::string name, const std::function<double(double)>& fn, const CurveFitSpec& spec) {
    const std::string where = "sim::MonotoneCurve::fit(): curve " + name + ": ";
    if (!fn) throw std::invalid_argument(where + "no function given");
    if (spec.count < 2)
        throw std::invalid_argument(where + "count " + std::to_string(spec.count) + " must be at least 2");
    if (!std::isfinite(spec.xmin) || !std::isfinite(spec.xmax) || !(spec.xmin < spec.xmax))
        throw std::invalid_argument(where + "range [" + formatNumber(spec.xmin, 12) + ", " +
                                    formatNumber(spec.xmax, 12) + "] must be finite with xmin < xmax");
    if (spec.spacing == CurveSpacing::Geometric && !(spec.xmin > 0))
        throw std::invalid_argument(where + "geometric spacing needs xmin > 0 (xmin=" + formatNumber(spec.xmin, 12) +
                                    ")");
    std::vector<CurvePoint> pts(static_cast<std::size_t>(spec.count));
    const double last = spec.count - 1;
    for (int k = 0; k < spec.count; ++k) {
        double x;
        if (k == 0)
            x = spec.xmin;
        else if (k == spec.count - 1)
            x = spec.xmax;
        else if (spec.spacing == CurveSpacing::Geometric)
            x = spec.xmin * std::exp(std::log(spec.xmax / spec.xmin) * (k / last));
        else
            x = spec.xmin + (spec.xmax - spec.xmin) * (k / last);
        pts[static_cast<std::size_t>(k)] = {x, fn(x)};
    }
    return MonotoneCurve(std::move(name), std::move(pts), spec.shape);
}

void MonotoneCurve::check(const std::vector<CurvePoint>& p) const {
    const std::string where = (m_context.empty() ? std::string() : m_context + ": ") + "curve " + m_name + ": ";
    if (p.size() < 2)
        throw InputError(where + "needs at least 2 control points (has " + std::to_string(p.size()) + ")");
    for (std::size_t i = 0; i < p.size(); ++i) {
        const std::string point = "control point " + std::to_string(i) + " (x=" + formatNumber(p[i].x, 12) +
                                  ", y=" + formatNumber(p[i].y, 12) + ")";
        if (!std::isfinite(p[i].x) || !std::isfinite(p[i].y)) throw InputError(where + point + " is not finite");
        if (i == 0) continue;
        if (!(p[i].x > p[i - 1].x))
            throw InputError(where + point + " does not lie right of point " + std::to_string(i - 1) +
                             " (x=" + formatNumber(p[i - 1].x, 12) + ")");
        if (m_shape == CurveShape::StrictlyIncreasing && !(p[i].y > p[i - 1].y))
            throw InputError(where + point + " does not increase over point " + std::to_string(i - 1) +
                             " (y=" + formatNumber(p[i - 1].y, 12) + ")");
    }
}

void MonotoneCurve::validate() const {
    check(m_points);
}

void MonotoneCurve::rebuild() {
    const std::size_t n = m_points.size();
    const auto& p = m_points;
    const std::size_t k = std::min<std::size_t>(5, n);
    m_slopes.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t lo = std::min(i >= 2 ? i - 2 : 0, n - k);
        m_slopes[i] = lagrangeSlope(p, lo, lo + k - 1, i);
    }
    std::vector<double> secant(n - 1);
    for (std::size_t i = 0; i + 1 < n; ++i)
        secant[i] = (p[i + 1].y - p[i].y) / (p[i + 1].x - p[i].x);
    if (m_shape == CurveShape::StrictlyIncreasing) {
        for (std::size_t i = 0; i < n; ++i) {
            const double bound = 3.0 * (i == 0       ? secant[0]
                                        : i + 1 == n ? secant[n - 2]
                                                     : std::min(secant[i - 1], secant[i]));
            m_slopes[i] = std::clamp(m_slopes[i], 0.0, bound);
        }
    }
    m_segments.assign(n, Segment{});
    m_cumulative.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        Segment& q = m_segments[i];
        q.x = p[i].x;
        q.y = p[i].y;
        q.m = m_slopes[i];
        if (i + 1 == n) break;
        const double h = p[i + 1].x - p[i].x;
        const double m0 = m_slopes[i], m1 = m_slopes[i + 1];
        q.c = (3.0 * secant[i] - 2.0 * m0 - m1) / h;
        q.d = (m0 + m1 - 2.0 * secant[i]) / (h * h);
        q.c3 = q.c / 3.0;
        q.d4 = q.d / 4.0;
    }
    const auto whole = [&](std::size_t i) { return segmentPrimitive(i, p[i + 1].x - p[i].x); };
    for (std::size_t i = 0; i + 1 < n; ++i)
        m_cumulative[i + 1] = m_cumulative[i] + whole(i);
    // ∫₁^{x_k} y, summed outward from the segment that holds 1 (or from the end point next to 1
    // when 1 lies on a linear extension), so that values near rest carry no cancellation.
    constexpr double rest = 1.0;
    std::size_t anchor;
    if (rest <= p.front().x) {
        const double s = rest - p.front().x;
        anchor = 0;
        m_segments[0].rest = -(s * (p.front().y + 0.5 * m_slopes.front() * s));
    } else if (rest >= p.back().x) {
        const double s = rest - p.back().x;
        anchor = n - 1;
        m_segments[n - 1].rest = -(s * (p.back().y + 0.5 * m_slopes.back() * s));
    } else {
        anchor = segment(rest);
        m_segments[anchor].rest = -segmentPrimitive(anchor, rest - p[anchor].x);
    }
    for (std::size_t i = anchor + 1; i < n; ++i)
        m_segments[i].rest = m_segments[i - 1].rest + whole(i - 1);
    for (std::size_t i = anchor; i-- > 0;)
        m_segments[i].rest = m_segments[i + 1].rest - whole(i);
    // Collinear control points with equal slopes: the cubics are that line up to rounding.
    constexpr double kLinearTolerance = 1e-13;
    const double m0 = m_slopes.front();
    m_linear = true;
    for (std::size_t i = 0; i < n && m_linear; ++i) {
        const double run = p[i].x - p[0].x;
        const double line = p[0].y + m0 * run;
        m_linear = std::abs(p[i].y - line) <= kLinearTolerance * (std::abs(p[i].y) + std::abs(m0 * run)) &&
                   std::abs(m_slopes[i] - m0) <= kLinearTolerance * std::abs(m0);
    }
    // The line through the control point nearest to rest, so that f′(1) keeps the value of an
    // authored point at 1 exactly.
    std::size_t nearest = 0;
    for (std::size_t i = 1; i < n; ++i)
        if (std::abs(p[i].x - rest) < std::abs(p[nearest].x - rest)) nearest = i;
    m_line = Segment{};
    m_line.x = p[nearest].x;
    m_line.y = p[nearest].y;
    m_line.m = m_slopes[nearest];
    m_line.rest = m_line.y + m_line.m * (rest - m_line.x); // y(1)
    buildLookup();
}

void MonotoneCurve::buildLookup() {
    // Bucket b of x is clamp(floor(map(x)), 0, B − 1) with map non-decreasing, so control points
    // in buckets below b lie left of any x in bucket b: segment(x) ≥ first[b], where first[b] is
    // the last segment start in a bucket below b. Likewise segment(x) ≤ first[b + 1]. The table
    // is sized (per map, doubling B) until no bucket holds two segment starts; then one compare
    // finishes a lookup.
    const std::size_t n = m_points.size();
    const std::size_t segments = n - 1;
    const auto build = [&](BucketMap map, std::size_t buckets) {
        m_bucketMap = map;
        const double lo = map == BucketMap::Log2 ? log2Monotone(m_points.front().x) : m_points.front().x;
        const double hi = map == BucketMap::Log2 ? log2Monotone(m_points.back().x) : m_points.back().x;
        m_bucketOrigin = lo;
        m_bucketScale = static_cast<double>(buckets) / (hi - lo);
        m_bucketMax = static_cast<double>(buckets - 1);
        m_bucketFirst.assign(buckets + 1, 0);
        // Segment starts k = 1..n−2 (k = 0 is every bucket's floor).
        std::size_t k = 1;
        for (std::size_t b = 1; b <= buckets; ++b) {
            while (k < segments && static_cast<std::size_t>(bucketCoordinate(m_points[k].x)) < b)
                ++k;
            m_bucketFirst[b] = static_cast<std::uint32_t>(k - 1);
        }
        m_bucketFirst[buckets] = static_cast<std::uint32_t>(segments - 1);
        bool single = true;
        for (std::size_t b = 0; b < buckets && single; ++b)
            single = m_bucketFirst[b + 1] - m_bucketFirst[b] <= 1;
        return single;
    };
    const bool logOk =
        m_points.front().x >= std::numeric_limits<double>::min() && std::isfinite(log2Monotone(m_points.back().x));
    constexpr std::size_t kMaxBucketsPerSegment = 16;
    for (std::size_t buckets = 2 * segments; buckets <= kMaxBucketsPerSegment * segments; buckets *= 2) {
        // Prefer the map that separates the points with fewer buckets (a smaller table).
        if (build(BucketMap::Linear, buckets) || (logOk && build(BucketMap::Log2, buckets))) {
            m_singleStep = true;
            return;
        }
    }
    m_singleStep = false;
    build(logOk ? BucketMap::Log2 : BucketMap::Linear, kMaxBucketsPerSegment * segments);
}

std::size_t MonotoneCurve::searchBucket(std::size_t lo, std::size_t hi, double x) const {
    // Last k in [lo, hi] with x_k ≤ x (x_lo ≤ x holds).
    while (lo < hi) {
        const std::size_t mid = (lo + hi + 1) / 2;
        if (m_segments[mid].x <= x)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

std::size_t MonotoneCurve::segment(double x) const {
    // First point with x_k > x, minus one, clamped to a valid segment.
    const auto it =
        std::upper_bound(m_points.begin(), m_points.end(), x, [](double v, const CurvePoint& q) { return v < q.x; });
    const std::size_t idx = static_cast<std::size_t>(it - m_points.begin());
    return std::clamp<std::size_t>(idx == 0 ? 0 : idx - 1, 0, m_points.size() - 2);
}

double MonotoneCurve::value(double x) const {
    const Segment& first = m_segments.front();
    const Segment& last = m_segments.back();
    if (x > first.x && x < last.x) {
        const Segment& q = m_segments[lookupInterior(x)];
        const double s = x - q.x;
        return (q.y + q.m * s) + s * s * (q.c + q.d * s);
    }
    const Segment& e = x <= first.x ? first : last;
    return e.y + e.m * (x - e.x);
}

double MonotoneCurve::derivative(double x) const {
    if (x <= m_points.front().x) return m_slopes.front();
    if (x >= m_points.back().x) return m_slopes.back();
    const Segment& q = m_segments[lookupInterior(x)];
    const double s = x - q.x;
    return q.m + s * (2.0 * q.c + 3.0 * s * q.d);
}

double MonotoneCurve::antiderivative(double x) const {
    if (x <= m_points.front().x) {
        const double s = x - m_points.front().x;
        return s * (m_points.front().y + 0.5 * m_slopes.front() * s);
    }
    if (x >= m_points.back().x) {
        const double s = x - m_points.back().x;
        return m_cumulative.back() + s * (m_points.back().y + 0.5 * m_slopes.back() * s);
    }
    const std::size_t k = lookupInterior(x);
    return m_cumulative[k] + segmentPrimitive(k, x - m_points[k].x);
}

double MonotoneCurve::segmentPrimitive(std::size_t k, double s) const {
    return primitive(m_segments[k], s);
}

double MonotoneCurve::integral(double a, double b) const {
    if (b < a) return -integral(b, a);
    // Split into the left extension, the spline and the right extension. Inside the spline,
    // short spans sum their segments directly (no cancellation of the cumulative sums, which
    // keeps energies near rest accurate); long spans use the cumulative table.
    const double x0 = m_points.front().x, xn = m_points.back().x;
    double sum = 0;
    if (a < x0) {
        const double y0 = m_points.front().y, m0 = m_slopes.front();
        const auto prim = [&](double t) { return (t - x0) * (y0 + 0.5 * m0 * (t - x0)); };
        sum += prim(std::min(b, x0)) - prim(a);
    }
    if (b > xn) {
        const double yn = m_points.back().y, mn = m_slopes.back();
        const auto prim = [&](double t) { return (t - xn) * (yn + 0.5 * mn * (t - xn)); };
        sum += prim(b) - prim(std::max(a, xn));
    }
    const double u = std::max(a, x0), v = std::min(b, xn);
    if (u < v) {
        const std::size_t ku = segment(u), kv = segment(v);
        const double su = u - m_points[ku].x, sv = v - m_points[kv].x;
        if (ku == kv) {
            sum += segmentPrimitive(ku, sv) - segmentPrimitive(ku, su);
        } else if (kv - ku <= 16) {
            const auto whole = [&](std::size_t k) { return segmentPrimitive(k, m_points[k + 1].x - m_points[k].x); };
            sum += whole(ku) - segmentPrimitive(ku, su);
            for (std::size_t k = ku + 1; k < kv; ++k)
                sum += whole(k);
            sum += segmentPrimitive(kv, sv);
        } else {
            sum += (m_cumulative[kv] - m_cumulative[ku]) + segmentPrimitive(kv, sv) - segmentPrimitive(ku, su);
        }
    }
    return sum;
}

void MonotoneCurve::setControlPoint(std::size_t i, double x, double y) {
    if (i >= m_points.size())
        throw std::out_of_range("sim::MonotoneCurve::setControlPoint(): index " + std::to_string(i) +
                                " out of range (curve " + m_name + " has " + std::to_string(m_points.size()) +
                                " control points)");
    auto edited = m_points;
    edited[i] = {x, y};
    check(edited);
    m_points = std::move(edited);
    rebuild();
}

std::size_t MonotoneCurve::insertControlPoint(double x, double y) {
    auto edited = m_points;
    const auto it =
        std::lower_bound(edited.begin(), edited.end(), x, [](const CurvePoint& q, double v) { return q.x < v; });
    const std::size_t idx = static_cast<std::size_t>(it - edited.begin());
    edited.insert(it, CurvePoint{x, y});
    check(edited);
    m_points = std::move(edited);
    rebuild();
    return idx;
}

void MonotoneCurve::removeControlPoint(std::size_t i) {
    if (i >= m_points.size())
        throw std::out_of_range("sim::MonotoneCurve::removeControlPoint(): index " + std::to_string(i) +
                                " out of range (curve " + m_name + " has " + std::to_string(m_points.size()) +
                                " control points)");
    auto edited = m_points;
    edited.erase(edited.begin() + static_cast<std::ptrdiff_t>(i));
    check(edited);
    m_points = std::move(edited);
    rebuild();
}

} // namespace viscera::sim
