#pragma once
/// Loading a verified case into a World and running a session on it.
#include "case/case_package.hpp"
#include "case/trust.hpp"
#include "haptics/device.hpp"
#include "render/corner_uv.hpp"
#include "render/scene_view.hpp"
#include "render/tool_meshes.hpp"
#include "runtime/assessment.hpp"
#include "runtime/haptic_rig.hpp"
#include "runtime/port_meter.hpp"
#include "runtime/timeline.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

struct LoadedCase {
    std::unique_ptr<vcase::CasePackage> package;
    vcase::Provenance provenance; ///< which bytes, signed by whom (vcase::checkProvenance)
    sim::SceneDesc scene;
    std::unique_ptr<sim::World> world;
    /// Per body: its painted light-sample classes per node (sample_map_file), empty when it has
    /// none. Loaded only when the case renders with painted sampling.
    std::vector<std::vector<uint8_t>> sampleMaps;
    /// The material maps of render.materials, decoded: (body or surface name, maps).
    std::vector<std::pair<std::string, std::shared_ptr<const render::MaterialMaps>>> materialMaps;
    /// Bodies drawn with UVs of their own ("render.materials.<body>.uv"): body name and corner UVs.
    std::vector<std::pair<std::string, std::vector<render::CornerUvF>>> cornerUvs;
    /// The scene's scenery meshes (scene.scenery[k]): drawn, never simulated.
    std::vector<sim::TriMesh> scenery;
};

/// Verifies the package, checks it against `trust` (signature, expiry, rollback) before reading
/// its scene, parses the scene and assembles a World with only the subsystems the manifest
/// declares. Throws viscera::InputError naming the file, the field and the rule (also for a body's
/// sample map when the case does not render with painted sampling: it would not be used).
LoadedCase loadCase(const std::filesystem::path& casePath, const vcase::TrustPolicy& trust);

/// What the trainee sees of a loaded case: the world's bodies and surfaces
/// (render::SceneView::fromWorld) with the case's painted sample maps on the bodies and on the
/// fascia attached to them, and the case's material maps on the meshes they name.
render::SceneView caseView(const LoadedCase& loaded);

/// The session's geometry after a frame, as the trainee window's 3D view draws it.
struct LiveGeometry {
    std::vector<sim::Vec3> nodes;                   ///< nodes of every body, m, scene
    std::vector<std::vector<sim::Vec3>> surfaces;   ///< nodes of every fascia surface, m, scene
    std::vector<std::vector<uint8_t>> surfaceMasks; ///< per surface: intact triangles (empty: no cut)
    std::vector<std::vector<float>> surfaceHeat;    ///< per surface: vertex heat in [0, 1] (empty: none)
    std::vector<std::vector<uint8_t>> bodyTetMasks; ///< per body: intact tets (empty: not dissected)
    std::vector<std::vector<float>> bodyHeat;       ///< per body: node heat in [0, 1] (empty: none)
    render::ToolPoses tools;                        ///< instruments, probes, clips, needle, thread
};

/// What the trainee window draws; the physics thread writes it after every frame.
struct LiveView {
    std::mutex mutex;
    LiveState state;
    LiveGeometry geometry;
    std::vector<double> toolRadius;
    bool finished = false;
};

struct RunOptions {
    int frames = 300; ///< 0: run until *stop is set
    /// Called after every frame with (frames done, frames total); may be empty.
    std::function<void(int, int)> progress;
    haptics::Device* device = nullptr; ///< non-owning; null: no haptics subsystem
    std::string deviceSpec;
    bool realtime = false;  ///< servo thread + wall-clock pacing (console and keyboard need it)
    bool keepTrace = false; ///< keep every servo sample for the --trace CSV
    /// How the servo thread waits (--servo sleep|busy[:CPU]); cpu -1 = default.
    haptics::ServoWait servoWait = haptics::ServoWait::SleepSpin;
    int servoCpu = -1;
    int64_t servoSpinNs = -1;                ///< SleepSpin: spin this long before each deadline (-1: default 0.94 ms)
    const std::atomic<bool>* stop = nullptr; ///< set by the window when the trainee closes it
    LiveView* live = nullptr;                ///< filled every frame when set
    std::string trainee;                     ///< who ran it (--trainee), for the report's record
};

/// One rendered frame (--screenshot on the headless path): per-pass wall times.
struct RenderFigures {
    std::string device; ///< e.g. "llvmpipe (LLVM 15.0.6, 256 bits) — EGL 1.5 (surfaceless), OpenGL 4.5 core"
    std::string image;  ///< PNG path
    int width = 0, height = 0;
    double totalMs = 0, uploadMs = 0;
    struct Pass {
        std::string name;
        int eye = 0;
        double ms = 0;
    };
    std::vector<Pass> passes; ///< in execution order; a switched-off effect has no entry
};

struct SessionResult {
    std::string caseId, caseVersion, title;
    std::string trainee;       ///< RunOptions::trainee
    std::string startedUtc;    ///< "2026-12-05T19:50:00Z", when the session started
    vcase::Provenance package; ///< the package file's digest and signer
    std::vector<std::string> activeSubsystems;
    std::vector<sim::FrameRecord> frames;
    std::vector<sim::AccuracyRecord> accuracy;
    sim::Invariants invariants;
    double simTime = 0;               ///< s
    double wallTime = 0;              ///< s
    double frameDt = 0;               ///< s, the scene's frame time step (real time: one frame per dt)
    double maxNodeDisplacement = 0;   ///< m, largest node distance from the rest configuration over the run
    double finalNodeDisplacement = 0; ///< m, the same at the end
    size_t nodes = 0, tets = 0;
    /// Per body: its name, lumped mass and the extra inertia selective inertia scaling gave its
    /// nodes at load (World::addedInertiaKg), kg.
    struct BodyInertia {
        std::string name;
        double massKg = 0, addedKg = 0;
    };
    std::vector<BodyInertia> inertia;
    std::vector<std::string> errors;
    std::vector<std::string> warnings;    ///< e.g. a device that drives no tool (also logged when given)
    std::optional<HapticsResult> haptics; ///< present when the session ran a device
    TaskMetrics metrics;
    std::vector<TraceRow> trace;                        ///< when RunOptions::keepTrace
    std::optional<RenderFigures> render;                ///< when a frame was rendered (--screenshot)
    std::optional<sim::SutureSummary> suture;           ///< solver "fem" cases (needle and thread)
    std::vector<sim::SutureFrameRecord> sutureFrames;   ///< one per frame of a "fem" case
    std::optional<sim::InteractionSummary> interaction; ///< cases with scripted instruments
    SessionTimeline timeline;       ///< tool tips, forces and task events over the run (plots, report)
    std::vector<PortFigures> ports; ///< tools through trocar ports (port_meter.hpp)
    /// Paced sessions (a device on the wall clock): the physics' real-time factor estimated from
    /// the first frames (RealTimeWatch); 0 when not estimated.
    double realTimeEstimate = 0;
    /// m, scene: the needle's punctures in thread order (suturing cases).
    std::vector<Eigen::Vector3d> puncturePoints;
    Assessment assessment; ///< the metrics and, for a case with an assessment block, the verdict
    bool ok() const { return errors.empty() && invariants.allFinite; }
};

/// Real-time factor of physics: simulated time per wall time of the physics step, dt / step
/// (dt in s, step in ms). ≥ 1: physics keeps up with real time; below 1 the trainee sees the
/// tissue in slow motion. 0 when the step time is unknown (≤ 0).
inline double realTimeFactor(double dt, double stepMs) {
    return stepMs > 0 ? dt * 1e3 / stepMs : 0.0;
}

/// Frames a replay of `duration` s runs at the frame time step `dt`: its length and 0.5 s more (the
/// tissue settles after the last motion); 300 when dt is not positive. The studio's rehearsal and
/// the case replay tests run a replay this long.
int replayFrames(double duration, double dt);

/// Steps the world `frames` times, recording per-frame figures and invariants. Never throws.
SessionResult runSession(LoadedCase& loaded, const RunOptions& options);

} // namespace viscera::player
