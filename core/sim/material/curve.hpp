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
/// Cost: value/derivative/integral are O(log n) (a binary search for the segment); an edit
/// rebuilds the O(n) segment table.
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
    MonotoneCurve(std::string name, std::vector<CurvePoint> points,
                  CurveShape shape = CurveShape::StrictlyIncreasing, std::string context = {});

    /// Control points x_k = spaced over [xmin, xmax], y_k = fn(x_k): the interpolant of the
    /// samples. Throws std::invalid_argument for a bad spec (count < 2, xmin ≥ xmax, Geometric
    /// with xmin ≤ 0) and viscera::InputError when a sample is non-finite or, with
    /// StrictlyIncreasing, does not increase.
    static MonotoneCurve fit(std::string name, const std::function<double(double)>& fn,
                             const CurveFitSpec& spec);

    double value(double x) const;      ///< y(x)
    double derivative(double x) const; ///< dy/dx
    /// ∫_a^b y(x) dx, exact for the piecewise polynomial (and the linear extensions); b < a
    /// gives the negative.
    double integral(double a, double b) const;
    /// ∫_{x_0}^x y(t) dt (x_0 = first control point).
    double antiderivative(double x) const;

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
    void check(const std::vector<CurvePoint>& points) const;
    void rebuild();
    std::size_t segment(double x) const; ///< k with x_k ≤ x < x_{k+1}, clamped to [0, n−2]
    double segmentPrimitive(std::size_t k, double s) const; ///< ∫ over [x_k, x_k + s]

    std::string m_name;
    std::string m_context;
    CurveShape m_shape;
    std::vector<CurvePoint> m_points;
    std::vector<double> m_slopes;
    /// Per segment k: y(x) = y_k + m_k s + c_k s² + d_k s³, s = x − x_k.
    std::vector<double> m_c, m_d;
    std::vector<double> m_cumulative; ///< ∫_{x_0}^{x_k} y, per control point
};

} // namespace viscera::sim
