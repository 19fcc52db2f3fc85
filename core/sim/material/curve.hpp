#pragma once
/// Editable 1-D response curves for curve-based material editing [A §4.3.3].
///
/// A MonotoneCurve is a function y(x) given by control points (x_k, y_k), k = 0..n−1 (n ≥ 2),
/// x strictly increasing. In Valanis–Landel materials x is a principal stretch or a product of
/// stretches (dimensionless) and y is f′, g′ or h′ (Pa).
///
/// Representation: a C1 piecewise-cubic Hermite interpolant through the control points (a cubic
/// spline with a double knot at every control point; the curve passes through every point).
/// The slope m_k at point k is the derivative at x_k of the polynomial through the (up to) five
/// nearest control points (4th-order accurate on smooth data, exact on cubics). With
/// CurveShape::StrictlyIncreasing the slopes then go through the monotonicity filter of
/// Hyman (1983), m_k ← clamp(m_k, 0, 3·min(δ_{k−1}, δ_k)) with δ the secant slopes, which is
/// the Fritsch–Carlson sufficient condition: the curve is then strictly increasing between the
/// first and last control point and non-decreasing everywhere. On smooth data sampled finely the
/// filter is inactive, so fitted curves keep the 4th-order accuracy.
///
/// Outside [x_0, x_{n−1}] the curve continues linearly with the end slopes (C1 at the ends), so
/// value, derivative and integral are finite for every finite x.
///
/// A curve whose control points and slopes all lie on one line (within 1e-13 relative: the
/// linear f′ of the Neo-Hookean and corotated presets, a constant g′) is evaluated by sample()
/// as that line (through the control point nearest to x = 1), with no segment lookup; value(),
/// derivative() and integral() keep evaluating the interpolant, which differs from the line by
/// the rounding noise in its cubic coefficients (< 1e-13 relative).
///
/// Cost: value, derivative, sample, integralFromRest and antiderivative are O(1): the segment is
/// found from a bucket table over x (uniform spacing) or over a monotone piecewise-linear log2 x
/// (geometric spacing), built so that a bucket holds at most one control point, then one compare;
/// control-point spacings that no table up to 16 buckets per segment separates fall back to a
/// binary search inside the bucket. integral(a, b) is O(log n). The per-point data of the
/// piecewise polynomial lie in one 64-byte record, so a lookup touches two cache lines. An edit
/// rebuilds the O(n) tables.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace viscera::sim {

struct CurvePoint {
    double x = 0; ///< abscissa (stretch or stretch product, dimensionless)
    double y = 0; ///< value (Pa for f′, g′, h′)
};

enum class CurveShape {
    StrictlyIncreasing, ///< control values must increase strictly; the curve is monotone
    Unconstrained,      ///< any finite values; plain 4th-order Hermite interpolation, no filter
};

enum class CurveSpacing {
    Uniform,   ///< x_k equally spaced
    Geometric, ///< x_k equally spaced in log x (requires xmin > 0); resolves small stretches
};

/// Sampling of an analytic function for MonotoneCurve::fit().
struct CurveFitSpec {
    double xmin = 0.1;
    double xmax = 10.0;
    int count = 65; ///< number of control points, ≥ 2
    CurveSpacing spacing = CurveSpacing::Geometric;
    CurveShape shape = CurveShape::StrictlyIncreasing;
};

class MonotoneCurve {
public:
    /// `name` names the curve in messages ("f'", "h'"); `context` prefixes them
    /// ("material 'liver'"). Throws viscera::InputError when the points are invalid (see
    /// validate()).
    MonotoneCurve(std::string name, std::vector<CurvePoint> points, CurveShape shape = CurveShape::StrictlyIncreasing,
                  std::string context = {});

    /// Control points x_k = spaced over [xmin, xmax], y_k = fn(x_k): the interpolant of the
    /// samples. Throws std::invalid_argument for a bad spec (count < 2, xmin ≥ xmax, Geometric
    /// with xmin ≤ 0) and viscera::InputError when a sample is non-finite or, with
    /// StrictlyIncreasing, does not increase.
    static MonotoneCurve fit(std::string name, const std::function<double(double)>& fn, const CurveFitSpec& spec);

    double value(double x) const;      ///< y(x)
    double derivative(double x) const; ///< dy/dx
    /// ∫_a^b y(x) dx, exact for the piecewise polynomial (and the linear extensions); b < a
    /// gives the negative.
    double integral(double a, double b) const;
    /// ∫_{x_0}^x y(t) dt (x_0 = first control point).
    double antiderivative(double x) const;

    /// ∫₁ˣ y(t) dt: the primitive that vanishes at x = 1, the rest value of a stretch or a
    /// stretch product (the rest-normalized Valanis–Landel terms f, g, h, [A eq. 4.18]). Equal to
    /// integral(1, x) up to rounding and exactly 0 at x = 1. Near 1 the value is a difference
    /// within one segment (no cancellation of large cumulative sums). O(1).
    double integralFromRest(double x) const { return sample(x).integralFromRest; }

    struct Sample {
        double value = 0;            ///< y(x)
        double integralFromRest = 0; ///< ∫₁ˣ y(t) dt
    };
    /// value(x) and integralFromRest(x) from one segment lookup: the per-tet hot path of
    /// Valanis–Landel densities. O(1), no allocation. Bit-identical to value(x) except on a
    /// linear curve (see above).
    Sample sample(double x) const;
    /// The lookup of sample() split in two, so that it can start from an early estimate of the
    /// abscissa: sampleFrom(x, locate(y)) == sample(x) (bit-identical) for any x and y, and
    /// costs only the polynomial when x lies in the segment of y. (Valanis–Landel: locate at
    /// det F before the SVD, sample at J = σ1 σ2 σ3 after it.)
    std::size_t locate(double y) const;
    Sample sampleFrom(double x, std::size_t located) const;

    const std::vector<CurvePoint>& controlPoints() const { return m_points; }
    std::size_t size() const { return m_points.size(); }
    /// Slopes m_k used at the control points (after the monotonicity filter).
    const std::vector<double>& slopes() const { return m_slopes; }
    CurveShape shape() const { return m_shape; }
    const std::string& name() const { return m_name; }
    const std::string& context() const { return m_context; }
    void setContext(std::string context) { m_context = std::move(context); }

    /// Edits. Each checks the edited point list as validate() does and throws
    /// viscera::InputError leaving the curve unchanged when it is invalid; an index out of range
    /// throws std::out_of_range. Indices are 0-based.
    void setControlPoint(std::size_t i, double x, double y);
    /// Inserts at the position that keeps x sorted; returns the new point's index.
    std::size_t insertControlPoint(double x, double y);
    void removeControlPoint(std::size_t i);

    /// Throws viscera::InputError naming the context, the curve and the offending control point,
    /// e.g. "material 'liver': curve h': control point 3 (x=1.2, y=0.5) does not increase over
    /// point 2 (y=0.7)". Rules: at least 2 points; finite coordinates; x strictly increasing;
    /// with StrictlyIncreasing, y strictly increasing.
    void validate() const;

private:
    /// Control point k and the cubic of segment k: y(x) = y + m s + c s² + d s³, s = x − x_k,
    /// with its primitive s (y + s (m/2 + s (c/3 + s d/4))) (c3 = c/3, d4 = d/4). The last record
    /// (k = n − 1) has c = d = 0 and serves the linear extension beyond x_{n−1}.
    struct alignas(64) Segment {
        double x = 0, y = 0, m = 0, c = 0, d = 0;
        double rest = 0; ///< ∫₁^{x_k} y
        double c3 = 0, d4 = 0;
    };
    /// How lookupInterior() maps x to a bucket: Linear: (x − origin) · scale; Log2:
    /// (log2Monotone(x) − origin) · scale (geometric spacing, x_0 > 0).
    enum class BucketMap : std::uint8_t { Linear, Log2 };

    void check(const std::vector<CurvePoint>& points) const;
    void rebuild();
    void buildLookup();
    std::size_t segment(double x) const; ///< k with x_k ≤ x < x_{k+1}, clamped to [0, n−2]
    /// segment(x) for x_0 ≤ x < x_{n−1}, O(1) (see buildLookup()).
    std::size_t lookupInterior(double x) const;
    std::size_t searchBucket(std::size_t lo, std::size_t hi, double x) const;
    double bucketCoordinate(double x) const;
    double segmentPrimitive(std::size_t k, double s) const; ///< ∫ over [x_k, x_k + s]
    /// Non-decreasing, piecewise-linear stand-in for 2^52 (log2 x + 1022) (x > 0): the bits of x
    /// read as an integer (biased exponent, then mantissa). Exact monotonicity is all the bucket
    /// table relies on.
    static double log2Monotone(double x) { return static_cast<double>(std::bit_cast<std::int64_t>(x)); }
    /// Integrand primitive of a record at offset s: s (y + s (m/2 + s (c/3 + s d/4))), in
    /// Estrin's order (shorter dependency chain than Horner's). The rest table is built with
    /// the same expression, so that integralFromRest(1) is exactly 0.
    static double primitive(const Segment& q, double s) {
        const double s2 = s * s;
        return s * ((q.y + 0.5 * q.m * s) + s2 * (q.c3 + q.d4 * s));
    }

    std::string m_name;
    std::string m_context;
    CurveShape m_shape;
    std::vector<CurvePoint> m_points;
    std::vector<double> m_slopes;
    std::vector<Segment> m_segments;  ///< per control point (n records)
    std::vector<double> m_cumulative; ///< ∫_{x_0}^{x_k} y, per control point
    /// Bucket table: segment(x) lies in [m_bucketFirst[b], m_bucketFirst[b + 1]] for x in bucket b
    /// (B + 1 entries). With m_singleStep that range holds at most two segments.
    std::vector<std::uint32_t> m_bucketFirst;
    BucketMap m_bucketMap = BucketMap::Linear;
    bool m_singleStep = false;
    /// When m_linear, sample() evaluates the line through the control point nearest to x = 1:
    /// y = m_line.y + m_line.m (x − m_line.x), ∫₁ˣ y = (x − 1) (m_line.rest + m_line.m (x − 1)/2)
    /// with m_line.rest = y(1) (anchored at rest: exactly 0 there, no cancellation near it).
    bool m_linear = false;
    Segment m_line;
    double m_bucketOrigin = 0, m_bucketScale = 0, m_bucketMax = 0; ///< m_bucketMax = B − 1
};

inline double MonotoneCurve::bucketCoordinate(double x) const {
    const double t = ((m_bucketMap == BucketMap::Log2 ? log2Monotone(x) : x) - m_bucketOrigin) * m_bucketScale;
    return std::max(0.0, std::min(t, m_bucketMax)); // NaN → 0 (min keeps t, max drops it)
}

inline std::size_t MonotoneCurve::lookupInterior(double x) const {
    const auto b = static_cast<std::size_t>(static_cast<std::int64_t>(bucketCoordinate(x)));
    const std::size_t k = m_bucketFirst[b];
    if (m_singleStep) return k + (x >= m_segments[k + 1].x ? 1 : 0);
    return searchBucket(k, m_bucketFirst[b + 1], x);
}

inline MonotoneCurve::Sample MonotoneCurve::sample(double x) const {
    if (m_linear) {
        const double t = x - 1.0;
        return {m_line.y + m_line.m * (x - m_line.x), t * (m_line.rest + 0.5 * m_line.m * t)};
    }
    const Segment& first = m_segments.front();
    const Segment& last = m_segments.back();
    if (x > first.x && x < last.x) [[likely]] {
        const Segment& q = m_segments[lookupInterior(x)];
        const double s = x - q.x, s2 = s * s;
        return {(q.y + q.m * s) + s2 * (q.c + q.d * s), q.rest + primitive(q, s)};
    }
    // Linear extensions (NaN takes the right one and stays NaN).
    const Segment& e = x <= first.x ? first : last;
    const double s = x - e.x;
    return {e.y + e.m * s, e.rest + s * (e.y + 0.5 * e.m * s)};
}

inline std::size_t MonotoneCurve::locate(double y) const {
    // n − 1 (no segment) for the linear paths of sample().
    if (m_linear || !(y > m_segments.front().x && y < m_segments.back().x)) return m_segments.size() - 1;
    return lookupInterior(y);
}

inline MonotoneCurve::Sample MonotoneCurve::sampleFrom(double x, std::size_t located) const {
    if (located + 1 < m_segments.size()) {
        // x in [x_k, x_{k+1}) ⊂ [x_0, x_{n−1}): segment k is what sample() finds (at x = x_0 its
        // extension formula gives the same numbers, s = 0).
        const Segment& q = m_segments[located];
        if (x >= q.x && x < m_segments[located + 1].x) [[likely]] {
            const double s = x - q.x, s2 = s * s;
            return {(q.y + q.m * s) + s2 * (q.c + q.d * s), q.rest + primitive(q, s)};
        }
    }
    return sample(x);
}

} // namespace viscera::sim
