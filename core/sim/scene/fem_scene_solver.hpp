#pragma once
/// Solver "fem" behind the SceneSolver interface: the suturing simulation [B §2.2, §3] on the
/// scene's bodies merged into one mesh, the needle following the case's recorded trajectory one
/// frame per step (the last frame is held after the end), per-body position mirrors and, when
/// the scene names two bodies, the closure gauge. Quasi-static: no velocities, no surfaces,
/// probes, gravity or accuracy sampling (create() rejects scenes that use them).
#include "sim/scene/scene_solver.hpp"
#include "sim/suture/anastomosis.hpp"

#include <array>
#include <memory>
#include <optional>

namespace viscera::sim {

class FemSceneSolver final : public SceneSolver, public SutureReport, public NeedleDrive {
public:
    /// Throws viscera::InputError naming in.origin ("<origin>: scene: solver 'fem': <rule>", or
    /// "... cannot be simulated stably: ..." for a mesh the FEM refuses).
    static std::unique_ptr<FemSceneSolver> create(const SceneSolverInputs& in);
    ~FemSceneSolver() override;

    StepStats step(const FrameClock& clock) override;
    bool recordFrame(const FrameClock& clock) override;
    void sampleAccuracy(const FrameClock&, std::vector<AccuracyRecord>&) override {} // rejected at create()
    const std::vector<Vec3>& positions(size_t body) const override { return m_bodyX[body]; }
    /// The FEM has no surfaces: throws std::out_of_range.
    const std::vector<Vec3>& surfacePositions(size_t s) const override;
    double totalEnergy() const override; ///< J, elastic energy of the FEM
    /// Quasi-static: the velocities are zero (#V of the body).
    const std::vector<Vec3>& velocities(size_t body) const override { return m_zeroV[body]; }
    /// Not supported (probes are rejected at create()): throws std::invalid_argument.
    void setState(size_t body, const std::vector<Vec3>& x, const std::vector<Vec3>& v) override;
    const std::vector<Vec3>& surfaceVelocities(size_t s) const override;
    void setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v) override;
    const SutureReport* suture() const override { return this; }
    NeedleDrive* needleDrive() override { return this; }
    const NeedleDrive* needleDrive() const override { return this; }
    NeedleFrame restFrame() const override { return m_trajectory.front(); }
    /// The step moves the needle at most kMaxDrivenMove and kMaxDrivenTurnDeg per frame towards
    /// the frame's pose (a jump of the master drags the tissue over several frames, not one).
    void drive(const NeedleFrame& frame) override { m_drive = frame; }
    static constexpr double kMaxDrivenMove = 0.0005; ///< m per frame
    static constexpr double kMaxDrivenTurnDeg = 4.0; ///< degrees per frame
    Vec3 needleForce() const override { return m_last.needleForceVector; }
    double threadTension() const override { return m_last.threadTension; }

    const std::vector<SutureFrameRecord>& frames() const override { return m_frames; }
    SutureSummary summary() const override;
    NeedleCurve needleCurve() const override { return m_suture->curve(); }
    double needleLength() const override;
    std::vector<Vec3> threadPath() const override;

private:
    FemSceneSolver();
    std::vector<Vec3> gaugePositions() const;

    std::unique_ptr<SutureSimulation> m_suture;
    std::vector<NeedleFrame> m_trajectory;
    bool m_thread = false; ///< pulls of the trajectory are applied
    NeedleSpec m_needle;
    std::vector<int32_t> m_offsets;         ///< first merged node of each body
    std::vector<std::vector<Vec3>> m_bodyX; ///< per-body positions
    std::vector<std::vector<Vec3>> m_zeroV; ///< per-body zero velocities
    std::unique_ptr<TetMesh> m_gaugeMesh;   ///< the two gauged bodies, merged
    std::unique_ptr<ClosureGauge> m_gauge;
    std::array<size_t, 2> m_gaugeBodies{};
    SutureStepStats m_last;             ///< of the last step()
    std::optional<NeedleFrame> m_drive; ///< a device's frame, instead of the trajectory's
    std::vector<SutureFrameRecord> m_frames;
    double m_initialGap = 0, m_sampledPenetration = 0;
};

} // namespace viscera::sim
