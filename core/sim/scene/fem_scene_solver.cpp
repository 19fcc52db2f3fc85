#include "sim/scene/fem_scene_solver.hpp"

#include "sim/util/error.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viscera::sim {

FemSceneSolver::FemSceneSolver() = default;
FemSceneSolver::~FemSceneSolver() = default;

std::unique_ptr<FemSceneSolver> FemSceneSolver::create(const SceneSolverInputs& in) {
    const SceneDesc& scene = in.scene;
    const auto& meshes = in.meshes;
    const std::string& origin = in.origin;
    const SutureSceneDesc& sd = *scene.suture;
    auto fail = [&](const std::string& rule) -> void { throw InputError(origin + ": scene: solver 'fem': " + rule); };
    if (!scene.surfaces.empty()) fail("surfaces (fascia) are not supported");
    if (!scene.tools.empty()) fail("haptic probes are not supported");
    if (scene.accuracy) fail("'accuracy' sampling is not supported");
    if (scene.xpbd.gravity.squaredNorm() > 0) fail("gravity is not used by the quasi-static FEM; remove it");
    if (!(scene.xpbd.dt > 0)) fail("dt must be positive");
    std::vector<int32_t> fixed;
    std::vector<int32_t> offsets;
    std::vector<const TetMesh*> parts;
    int32_t offset = 0;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodyDesc& b = scene.bodies[i];
        if (!b.embeddedIn.empty() || b.strainLimits || !b.nodeWeights.empty())
            fail("bodies[" + std::to_string(i) + "]: embedding, strain limits and node weights are not supported");
        if (b.material.youngsModulus != scene.bodies[0].material.youngsModulus ||
            b.material.poissonRatio != scene.bodies[0].material.poissonRatio)
            fail("bodies[" + std::to_string(i) +
                 "].material: all bodies need the same youngs_modulus and poisson_ratio");
        for (int32_t v : b.fixedNodes) {
            if (v >= static_cast<int32_t>(meshes[i]->vertexCount()))
                fail("bodies[" + std::to_string(i) + "].fixed_nodes: node " + std::to_string(v) + " is out of range");
            fixed.push_back(v + offset);
        }
        offsets.push_back(offset);
        parts.push_back(meshes[i].get());
        offset += static_cast<int32_t>(meshes[i]->vertexCount());
    }
    std::vector<NeedleFrame> trajectory = parseTrajectory(sd.trajectoryText, origin + ": " + sd.trajectoryPath);
    SutureSettings settings = sd.settings;
    settings.fem.youngsModulus = scene.bodies[0].material.youngsModulus;
    settings.fem.poissonRatio = scene.bodies[0].material.poissonRatio;
    // Refactorization off the step: the worker takes the idle rest of the frames (about 30 ms of
    // work against 10 frames of 15 ms idle each) and is joined 10 solves after the request; the new
    // factor is swapped in at a solve fixed by counts alone, so a session is repeatable
    // (CorotationalFem, RefactorMode::Background; a late worker's factor is computed by the solve).
    settings.fem.refactorMode = RefactorMode::Background;
    settings.fem.refactorLatencySteps = 10;
    std::unique_ptr<FemSceneSolver> f(new FemSceneSolver());
    try {
        f->m_suture = SutureSimulation::create(mergeMeshes(parts, nullptr), fixed, settings, trajectory.front().pose);
    } catch (const std::invalid_argument& e) {
        throw InputError(origin + ": scene cannot be simulated stably: " + e.what());
    }
    if (!sd.gauge[0].empty()) {
        for (int k = 0; k < 2; ++k) {
            size_t i = 0;
            while (i < scene.bodies.size() && scene.bodies[i].name != sd.gauge[k])
                ++i;
            if (i == scene.bodies.size()) fail("suture.gauge: '" + sd.gauge[k] + "' is not a body of the scene");
            f->m_gaugeBodies[k] = i;
        }
        f->m_gaugeMesh = mergeMeshes({parts[f->m_gaugeBodies[0]], parts[f->m_gaugeBodies[1]]}, nullptr);
        f->m_gaugeMesh->requireLevel(3);
        f->m_gauge = std::make_unique<ClosureGauge>(*f->m_gaugeMesh,
                                                    static_cast<int32_t>(parts[f->m_gaugeBodies[0]]->vertexCount()));
    }
    f->m_trajectory = std::move(trajectory);
    f->m_thread = sd.thread;
    f->m_needle = settings.needle;
    f->m_offsets = std::move(offsets);
    for (const auto& m : meshes) {
        f->m_bodyX.push_back(m->positions());
        f->m_zeroV.emplace_back(m->vertexCount(), Vec3::Zero());
    }
    if (f->m_gauge) f->m_initialGap = f->m_gauge->measure(f->gaugePositions()).maxGap;
    return f;
}

std::vector<Vec3> FemSceneSolver::gaugePositions() const {
    std::vector<Vec3> x = m_bodyX[m_gaugeBodies[0]];
    x.insert(x.end(), m_bodyX[m_gaugeBodies[1]].begin(), m_bodyX[m_gaugeBodies[1]].end());
    return x;
}

StepStats FemSceneSolver::step(const FrameClock& clock) {
    NeedleFrame frame;
    if (m_drive) {
        frame = *m_drive;
        const Eigen::Isometry3d& now = m_suture->needlePose();
        if (frame.pose.matrix().allFinite()) {
            Vec3 move = frame.pose.translation() - now.translation();
            if (move.norm() > kMaxDrivenMove) move *= kMaxDrivenMove / move.norm();
            Eigen::AngleAxisd turn(frame.pose.linear() * now.linear().transpose());
            turn.angle() = std::min(turn.angle(), kMaxDrivenTurnDeg * M_PI / 180.0);
            frame.pose.linear() = turn.toRotationMatrix() * now.linear();
            frame.pose.translation() = now.translation() + move;
        }
    } else
        frame = m_trajectory[std::min<size_t>(static_cast<size_t>(clock.frame), m_trajectory.size() - 1)];
    if (!m_thread) frame.pull = 0;
    m_last = m_suture->step(frame);
    StepStats rec;
    rec.substeps = 1;
    rec.iterations = m_last.solves;
    const auto& x = m_suture->positions();
    double maxMove = 0;
    bool finite = m_last.finite;
    for (size_t b = 0; b < m_bodyX.size(); ++b)
        for (size_t v = 0; v < m_bodyX[b].size(); ++v) {
            const Vec3& p = x[m_offsets[b] + v];
            finite = finite && p.allFinite();
            maxMove = std::max(maxMove, (p - m_bodyX[b][v]).norm());
            m_bodyX[b][v] = p;
        }
    rec.maxDisplacement = maxMove;
    rec.finite = finite;
    return rec;
}

double FemSceneSolver::needleLength() const {
    return m_needle.length_();
}

std::vector<Vec3> FemSceneSolver::threadPath() const {
    std::vector<Vec3> path = m_thread ? m_suture->puncturePoints() : std::vector<Vec3>{};
    path.push_back(m_suture->curve().point(0.0));
    return path;
}

bool FemSceneSolver::recordFrame(const FrameClock& clock) {
    const SutureStepStats& st = m_last;
    SutureFrameRecord sr;
    sr.frame = clock.frame;
    sr.activeRows = st.activeRows;
    sr.rejectedRows = st.rejectedRows;
    sr.contacts = st.contacts;
    sr.punctures = st.punctures;
    sr.threadTension = st.threadTension;
    sr.needleForce = st.needleForce;
    sr.threadEngaged = st.threadEngaged;
    bool finite = std::isfinite(st.threadTension);
    if (m_gauge && clock.frame % 10 == 0) { // sampled, outside the timed step
        const ClosureMetrics cm = m_gauge->measure(gaugePositions());
        sr.maxGap = cm.maxGap;
        sr.maxPenetration = cm.maxPenetration;
        m_sampledPenetration = std::max(m_sampledPenetration, cm.maxPenetration);
        finite = finite && cm.finite;
    }
    m_frames.push_back(sr);
    return finite;
}

const std::vector<Vec3>& FemSceneSolver::surfacePositions(size_t) const {
    throw std::out_of_range("sim::FemSceneSolver::surfacePositions(): the suturing FEM has no surfaces");
}

double FemSceneSolver::totalEnergy() const {
    return m_suture->fem().elasticEnergy();
}

void FemSceneSolver::setState(size_t, const std::vector<Vec3>&, const std::vector<Vec3>&) {
    throw std::invalid_argument("sim::FemSceneSolver::setState(): the quasi-static FEM has no settable state");
}

const std::vector<Vec3>& FemSceneSolver::surfaceVelocities(size_t) const {
    throw std::invalid_argument("sim::FemSceneSolver::surfaceVelocities(): the suturing scene has no surfaces");
}

void FemSceneSolver::setSurfaceState(size_t, const std::vector<Vec3>&, const std::vector<Vec3>&) {
    throw std::invalid_argument("sim::FemSceneSolver::setSurfaceState(): the suturing scene has no surfaces");
}

SutureSummary FemSceneSolver::summary() const {
    SutureSummary s;
    for (const SutureFrameRecord& r : m_frames) {
        s.punctures = std::max(s.punctures, r.punctures);
        s.maxThreadTension = std::max(s.maxThreadTension, r.threadTension);
        s.maxActiveRows = std::max(s.maxActiveRows, r.activeRows);
        s.maxContacts = std::max(s.maxContacts, r.contacts);
    }
    if (!m_frames.empty()) s.finalThreadTension = m_frames.back().threadTension;
    if (m_gauge) {
        const ClosureMetrics cm = m_gauge->measure(gaugePositions());
        s.gauge = true;
        s.initialGap = m_initialGap;
        s.finalGap = cm.maxGap;
        s.maxPenetration = std::max(m_sampledPenetration, cm.maxPenetration);
        s.finite = cm.finite;
    }
    return s;
}

} // namespace viscera::sim
