#pragma once
/// Settings and per-frame statistics shared by the XPBD solvers [A §4.4.2].
#include "sim/mesh/tri_mesh.hpp"

#include <cstddef>
#include <functional>
#include <string>

namespace viscera::sim {

/// Default worker count: the CPUs the calling thread may run on (its affinity mask; else
/// std::thread::hardware_concurrency()) clamped to [1, 8], 2 when unknown.
int defaultXpbdThreads();

struct XpbdSettings {
    double dt = 1.0 / 60.0;           ///< frame time step, s
    int substeps = 10;                ///< substeps per frame
    int iterations = 1;               ///< constraint sweeps per substep
    double damping = 1.0;             ///< velocity damping rate, 1/s
    Vec3 gravity = Vec3(0, 0, -9.81); ///< m/s^2, world frame
    double maxSpeed = 20.0;           ///< m/s; faster nodes are clamped (counted in StepStats)
    /// Threads that share the constraint sweeps (1 = serial, on the calling thread). Constraints
    /// are graph-coloured, so results are bit-identical for every thread count.
    int threads = defaultXpbdThreads();
    /// Use the AVX2/FMA stable Neo-Hookean kernel when the CPU has it. false forces the portable
    /// scalar kernel (same equations; results differ from the SIMD kernel in the last bits).
    bool simd = true;
    /// After every iteration, the primal correction x ← x̃ + M⁻¹ ∇C(x)ᵀ λ (XpbdIteration::
    /// PrimalCorrected): iterations then converge to the implicit step's solution instead of
    /// levelling off O(h² k/m) away from it, at about 4 times the cost of a plain iteration
    /// (parallel like the sweeps, bit-identical for any thread count). Elastic tets only (no strain limits, membranes
    /// or ties); converges while the stiffness number h² k w/(ρ L²) is small, which the load-time stability check
    /// enforces.
    bool primalCorrection = false;
    /// Selective inertia scaling, applied by the scene solver at load (XpbdSceneSolver::create):
    /// a node of a tet over the stability limit at these substeps gets extra inertia, at most
    /// (inertiaScaling − 1) times its own lumped mass, so that the tet passes
    /// (stabilizingInertia, stability_check.hpp). Gravity on that node is scaled down by the same
    /// factor, so its weight and hence every static equilibrium stay as they were; only the
    /// dynamics of those nodes are slower. 1 = off.
    double inertiaScaling = 1.0;
};

/// Admissible ranges of XpbdSettings: validate() and the scene readers (scene_json.hpp) use
/// these, so scene.json and project.json get one rule.
struct XpbdLimits {
    static constexpr double maxDt = 0.1;             ///< s; dt in (0, maxDt]
    static constexpr int maxSubsteps = 1000;         ///< substeps in [1, maxSubsteps]
    static constexpr int maxIterations = 1000;       ///< iterations in [1, maxIterations]
    static constexpr double maxDamping = 1000;       ///< 1/s; damping in [0, maxDamping]
    static constexpr double maxGravity = 1000;       ///< m/s^2, |gravity|
    static constexpr int maxThreads = 64;            ///< threads in [1, maxThreads]
    static constexpr double maxInertiaScaling = 100; ///< inertiaScaling in [1, maxInertiaScaling]
    /// Work budget of a frame, checked when a world is assembled (player load, studio export):
    /// substeps × iterations × elements (tets and surface triangles) at most this many constraint
    /// solves, about a second per frame on a 2-core machine. Each limit above can hold alone while
    /// their product asks for hours per frame and gigabytes before the first one.
    static constexpr double maxConstraintSolvesPerFrame = 1e8;
};

/// Checks settings; empty string when valid, otherwise the rule that failed.
std::string validate(const XpbdSettings& s);

struct StepStats {
    bool finite = true; ///< false: the step produced a non-finite value and was undone
    int substeps = 0;
    int iterations = 0;
    double maxDisplacement = 0; ///< m, largest node displacement over the frame
    int speedClamps = 0;        ///< node-substeps whose speed was clamped to maxSpeed
};

/// Non-owning view of a solver's particles while a frame runs (handed to an XpbdIterationHook):
/// positions in metres (world frame), velocities in m/s and inverse masses in 1/kg (0 = fixed,
/// never move those). Indices are particle indices of the whole system; a tet body's nodes start
/// at its particle offset (XpbdSystem::tetParticleOffset; 0 for the single body of an
/// XpbdSolver). Valid only during the hook call. O(1) per access, no bounds check.
class XpbdParticles {
public:
    /// xw: 4 doubles per particle (x, y, z, inverse mass); v: one per particle or null.
    XpbdParticles(double* xw, Vec3* v, size_t count) : m_xw(xw), m_v(v), m_count(count) {}
    size_t size() const { return m_count; }
    Vec3 position(size_t i) const {
        const double* p = m_xw + 4 * i;
        return Vec3(p[0], p[1], p[2]);
    }
    void setPosition(size_t i, const Vec3& x) {
        double* p = m_xw + 4 * i;
        p[0] = x.x();
        p[1] = x.y();
        p[2] = x.z();
    }
    double inverseMass(size_t i) const { return m_xw[4 * i + 3]; }
    bool hasVelocities() const { return m_v != nullptr; }
    /// Meaningful in the velocity pass only (XpbdIterationInfo::velocityPass); zero without.
    Vec3 velocity(size_t i) const { return m_v ? m_v[i] : Vec3::Zero(); }
    void setVelocity(size_t i, const Vec3& v) {
        if (m_v) m_v[i] = v;
    }

private:
    double* m_xw;
    Vec3* m_v;
    size_t m_count;
};

/// Where in a frame an XpbdIterationHook is called.
struct XpbdIterationInfo {
    int substep = 0;   ///< 0 .. substeps − 1
    int iteration = 0; ///< 0 .. iterations − 1 (0: first sweep of the substep: reset multipliers)
    int substeps = 1;
    int iterations = 1;
    double h = 0; ///< substep length, s
    /// false: after sweep `iteration` (positions at the current iterate; velocities are those
    /// of the substep start). true: once per substep after its velocity update (v = Δx / h,
    /// damped, speed-clamped) and before the next prediction: positions final, velocities new;
    /// iteration == iterations. A contact model removes here the velocity its pushes produced.
    bool velocityPass = false;
};

/// Called after every constraint sweep of every substep (after elasticity, strain limits and
/// ties: its projections have the last word of the sweep), with the particles at the current
/// iterate, and once more per substep after the velocity update (info.velocityPass). Extra
/// constraints projected here (tool contacts, [A §5.2.5]) are part of the Gauss–Seidel
/// iteration like the built-in ones: the velocity update at the end of the substep sees their
/// moves (the velocity pass may then correct the velocities). Runs on one thread (one of the
/// solver's workers when threads > 1) while the others wait; it must not call back into the
/// solver. An exception thrown by the hook marks the frame non-finite (it is rolled back).
using XpbdIterationHook = std::function<void(XpbdParticles& particles, const XpbdIterationInfo& info)>;

} // namespace viscera::sim
