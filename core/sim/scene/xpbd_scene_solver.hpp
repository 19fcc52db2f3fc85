#pragma once
/// Solver "xpbd" behind the SceneSolver interface: every body, surface and coupling of the scene
/// in one XpbdSystem [A §4.2, §4.4.2]. A one-body scene without layers or instruments is built as
/// an XpbdSolver (the same system with one-body messages), which also carries the accuracy hooks
/// [A §4.4.3]; all state calls go through that solver's system. Scripted instruments (scene
/// "interaction") act inside the system's iterations and are stepped with it.
#include "sim/diagnostics/stability_check.hpp"
#include "sim/scene/scene_solver.hpp"
#include "sim/xpbd/xpbd_solver.hpp"
#include "sim/xpbd/xpbd_system.hpp"

#include <memory>
#include <optional>
#include <vector>

namespace viscera::sim {

/// The load-time stability figures of every tet body of an XPBD scene (in.scene.bodies order), as
/// XpbdSceneSolver::create checks them: with the inertia that hard ties add to embedded bodies
/// (XpbdSystem::tiedInertia), which the body-alone assessStability cannot see. For the studio's
/// live verdict. Throws viscera::InputError as create() does when the system cannot be built (bad
/// settings, material, embedding); an unstable body is no error here (its figures say so).
std::vector<StabilityFigures> assessSceneStability(const SceneSolverInputs& in);

class XpbdSceneSolver final : public SceneSolver {
public:
    /// Throws viscera::InputError naming in.origin: 'accuracy' on a scene with layers or several
    /// bodies, invalid solver settings, a body that cannot be simulated stably (material, curves,
    /// stiffness number, fixed nodes, inverted rest element, embedded node outside its cage, no
    /// free node), a bad interaction section.
    static std::unique_ptr<XpbdSceneSolver> create(const SceneSolverInputs& in);
    ~XpbdSceneSolver() override;

    StepStats step(const FrameClock& clock) override;
    bool recordFrame(const FrameClock&) override { return true; }
    void sampleAccuracy(const FrameClock& clock, std::vector<AccuracyRecord>& out) override;
    void setAccuracyCancel(const std::atomic<bool>* flag) override { m_accuracyCancel = flag; }
    const std::vector<Vec3>& positions(size_t body) const override { return m_sys->tetPositions(body); }
    const std::vector<Vec3>& surfacePositions(size_t s) const override { return m_sys->surfacePositions(s); }
    double totalEnergy() const override;
    const std::vector<Vec3>& velocities(size_t body) const override { return m_sys->tetVelocities(body); }
    void setState(size_t body, const std::vector<Vec3>& x, const std::vector<Vec3>& v) override;
    const std::vector<Vec3>& surfaceVelocities(size_t s) const override;
    void setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v) override;
    const InteractionRuntime* interaction() const override { return m_interaction.get(); }
    InteractionRuntime* mutableInteraction() override { return m_interaction.get(); }
    /// Per tet body: the extra inertia selective inertia scaling gave its nodes at load, kg (0 when
    /// none; XpbdSettings::inertiaScaling).
    const std::vector<double>& addedInertia() const { return m_addedInertia; }
    std::vector<double> addedInertiaKg() const override { return m_addedInertia; }

private:
    XpbdSceneSolver();
    std::unique_ptr<XpbdSolver> m_single;              ///< one tet body, no layers (accuracy hooks); or null
    std::unique_ptr<XpbdSystem> m_layered;             ///< several bodies and layers; or null
    XpbdSystem* m_sys = nullptr;                       ///< the one that runs: m_single's system or m_layered
    std::unique_ptr<InteractionRuntime> m_interaction; ///< null unless the scene has "interaction"
    std::optional<AccuracySampling> m_accuracy;
    const std::atomic<bool>* m_accuracyCancel = nullptr;
    bool m_primalCorrection = false;
    std::vector<double> m_addedInertia;
};

} // namespace viscera::sim
