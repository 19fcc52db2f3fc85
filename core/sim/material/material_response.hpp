#pragma once
/// Homogeneous test responses of an energy density: what a material does in a uniaxial tension
/// or compression test and in simple shear, for plotting beside its Valanis–Landel curves
/// [A §4.3.3, Fig. 4.6] and for fitting curves to test data (curve_fit.hpp).
///
/// Frames and units: the material frame is the test frame (x = loading axis); stretches are
/// dimensionless; stresses are first Piola–Kirchhoff (nominal: force per reference area), Pa.
///
/// Uniaxial test: F = diag(λ, t, t) with stress-free lateral faces, P22(t) = P33(t) = 0. For an
/// isotropic density P22 = P33 at this F, so one scalar equation P22(λ, t) = 0 fixes the lateral
/// stretch t. It is solved by a safeguarded Newton iteration (rtsafe: a Newton step from a
/// finite-difference slope, replaced by a bisection when it leaves the bracket or does not
/// shrink the residual fast enough) inside a bracket [a, b] with P22(a) < 0 < P22(b), found by
/// expanding geometrically from the initial guess in the direction the sign of P22 points to
/// (for a stable material P22 grows with t). t is searched in [kMinLateralStretch,
/// kMaxLateralStretch]; when no sign change lies there (or P22 is not finite) there is no
/// uniaxial state and the solve fails (see UniaxialResponse::solved). When P22 has several roots
/// (a non-convex edited material) the one found is the first sign change met going out from the
/// guess. Converged when the Newton step is below 1e-14 t or P22 is exactly zero.
///
/// Cost: a Valanis–Landel density is evaluated in its principal frame (stressPrincipal(), no
/// SVD): about 10 evaluations of P22 per cold solve, fewer warm; any other density through
/// EnergyDensity::stress(). Simple shear costs one stress() (one signed SVD). sampleResponsesInto() warm-starts each
/// point from the previous one and allocates only when the output vectors grow.
#include "sim/material/constraint_model.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace viscera::sim {

/// Homogeneous tests with one free face: the loading axis x stretched by λ, P11 the test's nominal
/// stress, the lateral stretch t solved so that the free face carries no load:
///   Uniaxial     F = diag(λ, t, t), P22 = P33 = 0 (tension and compression);
///   Equibiaxial  F = diag(λ, λ, t), P33 = 0 (x and y stretched alike; P22 = P11);
///   PlanarShear  F = diag(λ, 1, t), P33 = 0 (pure shear: y held, as in a wide strip).
/// The same safeguarded Newton search as the uniaxial solve, from t = λ^(-1/2), λ^(-2), λ^(-1)
/// (the incompressible values).
enum class LoadCase { Uniaxial, Equibiaxial, PlanarShear };
/// "uniaxial", "equibiaxial", "planar shear".
const char* loadCaseName(LoadCase c);

/// Search range of the lateral stretch t of the uniaxial solve (dimensionless).
inline constexpr double kMinLateralStretch = 1e-6;
inline constexpr double kMaxLateralStretch = 1e6;

struct UniaxialResponse {
    double stretch = 1;        ///< λ, the imposed axial stretch
    double nominalStress = 0;  ///< P11 (Pa); 0 when !solved
    double lateralStretch = 1; ///< t, with P22(λ, t) = 0; 1 when !solved
    double lateralStress = 0;  ///< residual P22 at t (Pa), rounding-level when solved
    int evaluations = 0;       ///< stress evaluations spent (bracket and Newton)
    bool solved = false;       ///< false: no lateral stretch in the search range frees the faces
};

/// Uniaxial nominal stress at axial stretch `stretch` (finite, > 0): F = diag(λ, t, t), t solved
/// from P22 = 0 (see the file comment). Throws viscera::InputError when there is no uniaxial
/// state, e.g. "sim::uniaxialNominalStress(): density 'valanis_landel', stretch 2: no lateral
/// stretch in [1e-06, 1] frees the lateral faces (P22 = 35 Pa at t = 1e-06, 120 Pa at t = 1)",
/// and std::invalid_argument for a stretch that is not finite and positive.
UniaxialResponse uniaxialNominalStress(const EnergyDensity& density, double stretch);

/// As uniaxialNominalStress() but never throws for a missing root: returns solved = false
/// (finite fields) instead. `lateralGuess` (> 0, e.g. the previous point's t) starts the search;
/// 0 picks λ^(-1/2) (the incompressible value). Precondition as above (std::invalid_argument).
UniaxialResponse solveUniaxial(const EnergyDensity& density, double stretch, double lateralGuess = 0);
/// The test `c` at axial stretch `stretch` (see LoadCase), as solveUniaxial: solved = false when no
/// t in the search range frees the face; nominalStress = P11, lateralStretch = t.
UniaxialResponse solveLoadCase(const EnergyDensity& density, LoadCase c, double stretch, double lateralGuess = 0);

struct ShearResponse {
    double shear = 0;                   ///< γ (dimensionless)
    double shearStress = 0;             ///< P12 (Pa)
    double normalStress[3] = {0, 0, 0}; ///< P11, P22, P33 (Pa): the Poynting normal stresses
};

/// Simple shear F = I + γ e1⊗e2 (x displaced in proportion to y): one stress evaluation.
/// Throws std::invalid_argument for a non-finite γ.
ShearResponse simpleShearStress(const EnergyDensity& density, double gamma);

/// Sample points of sampleResponses(): `stretchCount` stretches spaced uniformly over
/// [stretchMin, stretchMax] (0 < stretchMin < stretchMax), `shearCount` shears over
/// [0, shearMax] (shearMax > 0). A count may be 0 (that plot is skipped); 1 gives the lower end.
struct ResponseSampling {
    double stretchMin = 0.6, stretchMax = 1.6;
    int stretchCount = 101;
    double shearMax = 1.0;
    int shearCount = 101;
};

/// Plot data, one entry per sample point (structure of arrays).
struct ResponseCurves {
    std::vector<double> stretch;        ///< λ (uniaxial)
    std::vector<double> nominalStress;  ///< P11 (Pa); 0 where !solved
    std::vector<double> lateralStretch; ///< t
    std::vector<std::uint8_t> solved;   ///< 1 where the uniaxial state exists (plot only those)
    int unsolved = 0;                   ///< number of zeros in `solved`
    std::vector<double> shear;          ///< γ
    std::vector<double> shearStress;    ///< P12 (Pa)
};

/// Fills `out` (resized; no allocation once its vectors are large enough): the per-drag path of
/// the curve editor. ~0.15 ms for 100 + 100 points on a Valanis–Landel density. Throws
/// std::invalid_argument for a bad `sampling` (message names the field).
void sampleResponsesInto(const EnergyDensity& density, const ResponseSampling& sampling, ResponseCurves& out);
ResponseCurves sampleResponses(const EnergyDensity& density, const ResponseSampling& sampling = {});

} // namespace viscera::sim
