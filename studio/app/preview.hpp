#pragma once
/// The studio's live preview: the project (or a uniaxial specimen of the selected body's
/// material) simulated on a worker thread while the user edits.
///
/// submit() hands the worker the latest model and returns at once (the UI thread never waits
/// for the simulation). The worker takes the newest submitted model at the start of each frame,
/// with what changed since the last (Change, accumulated): an edit of materials, paint strokes or
/// solver settings is applied to the running world by the next frame (a new world from the cached
/// meshes, carrying positions and velocities over); one of material maps or light samples gives
/// a new view of the same world; a general edit compares the models and rebuilds the meshes only
/// when they changed. Before a material enters the preview its stability is assessed
/// (sim::assessStability, the player's load rule): an edit that would be unstable is shown as
/// a verdict ("needs at least 67 substeps") and the preview keeps the last stable material, so
/// no NaN reaches the screen. A frame whose state is not finite is never published; the world
/// restarts from rest instead.
///
/// Every `accuracyEvery` frames, once no edit came for kQuietMs, the selected body's state goes to a sampler thread
/// (lower priority; the preview never waits for it) that solves the frame's first substep from it with XPBD iteration
/// by iteration and with Newton to convergence (World's accuracy sampling on a world of that body alone): relative
/// error [A eq. 4.45] against wall time for the current settings, the live error plot. The Newton reference takes one
/// tet body, so in a layered scene the body's couplings to the other layers are left out, which the snapshot says
/// (accuracyOf).
#include "app/document.hpp"
#include "project/project.hpp"
#include "render/scene_view.hpp"
#include "sim/scene/scene_solver.hpp"

#include <QObject>
#include <QString>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace viscera::studio {

class Preview : public QObject {
    Q_OBJECT
public:
    enum class Mode { Scene, Specimen };

    struct Snapshot {
        uint64_t serial = 0; ///< the submit() whose model this frame simulates
        /// Frames completed when the worker took that model (the frame after them shows it):
        /// frames from an edit to the preview showing it = appliedAfter − frames at submit().
        uint64_t appliedAfter = 0;
        uint64_t scene = 0;         ///< bumped whenever the meshes were rebuilt (new SceneView)
        int frame = 0;              ///< frames of the current world
        uint64_t frames = 0;        ///< frames simulated since start (all worlds)
        double stepMs = 0;          ///< physics wall time of the last frame
        std::deque<double> frameMs; ///< the last kHistory frames' physics ms
        std::vector<std::vector<sim::Vec3>> bodies, surfaces; ///< current positions, m
        std::optional<sim::AccuracyRecord> accuracy;          ///< XPBD trace of the last sampled frame
        std::optional<sim::AccuracyRecord> accuracyNewton;    ///< Newton's trace of that frame
        QString accuracyOf; ///< what was sampled: the scene, or one body of a layered scene alone
        QString verdict;    ///< stability verdict of the submitted materials
        bool verdictOk = true;
        QString error; ///< why the last submitted model is not shown (empty: it is)
    };
    static constexpr size_t kHistory = 240;
    /// Error sampling waits until no model was submitted for this long (ms).
    static constexpr int kQuietMs = 500;

    explicit Preview(QObject* parent = nullptr);
    ~Preview() override;

    /// The model to simulate (mode Specimen: a 20 × 20 × 60 mm specimen of body `body`'s
    /// material hanging under gravity, fixed at its top). Returns the serial of this submission;
    /// `framesAtSubmit` (optional) gets the frames completed at this moment.
    /// `what`: what changed since the last submission (a typed material or paint edit keeps the
    /// meshes without comparing the models).
    uint64_t submit(const Project& project, Mode mode, int body, uint64_t* framesAtSubmit = nullptr,
                    Change what = Change::everything());
    void setAccuracyEvery(int frames) { m_accuracyEvery = frames; }
    void setRealTime(bool on) { m_realTime = on; }
    /// Paused: edits are still taken (verdict, new world), no frame is simulated.
    void setPaused(bool on) {
        m_paused = on;
        m_wake.notify_all();
    }
    bool paused() const { return m_paused; }
    void stop();
    bool running() const { return m_thread.joinable(); }

    Snapshot snapshot() const;
    /// Bumped whenever the snapshot changes: a poll compares it before copying the snapshot.
    uint64_t revision() const { return m_revision; }
    /// The render meshes of the current world (rebuilt when Snapshot::scene changes).
    std::shared_ptr<const render::SceneView> sceneView() const;
    /// The built tet mesh of body `i` of the scene shown (rest state; null: none yet). What the
    /// stiffness painter maps its strokes through.
    std::shared_ptr<const sim::TetMesh> bodyMesh(int i) const;
    /// The cut surface of fascia `s` of the scene shown (rest state; null: none yet). What the
    /// stiffness painter paints a fascia's vertices on.
    std::shared_ptr<const sim::TriMesh> surfaceMesh(int s) const;

    /// A project holding the specimen of `material` (exposed for tests).
    static Project specimenProject(const Project& source, const sim::Material& material);

signals:
    /// A frame was published (queued to the receiver's thread).
    void frameReady();
    void logMessage(const QString& line);

private:
    struct Pending {
        Project project;
        Mode mode;
        int body;
        uint64_t serial;
        Change what;
    };
    struct Worker;
    void run();
    void sample();
    /// run()'s parts: apply a submitted model (a new world from new meshes, or new materials on
    /// the meshes built), then step and publish frames.
    void takeJob(Worker& w, const Pending& job, uint64_t takenAfter);
    /// A project without a body (File → New): no world; the view shows its scenery alone.
    void showEmpty(Worker& w, const Pending& job, uint64_t takenAfter);
    std::unique_ptr<sim::World> buildWorld(Worker& w, const Project& project, Mode mode, const std::string& origin);
    std::unique_ptr<sim::World> applyMaterials(Worker& w, const Project& project, const std::string& origin);
    void showMaps(Worker& w, const Project& project, const sim::World& world);
    void makeProbe(Worker& w, const Pending& job, const std::string& origin);
    /// One frame, published; false when the state became non-finite (the world restarts).
    bool stepFrame(Worker& w);
    void offerSample(Worker& w);
    void publishStatus(const std::function<void(Snapshot&)>& fn);

    /// A state to sample: the probe world (one body, accuracy on every frame) and the body's
    /// positions and velocities at preview frame `frame`.
    struct SampleJob {
        std::shared_ptr<sim::World> probe;
        std::vector<sim::Vec3> x, v;
        int frame = 0;
    };

    mutable std::mutex m_mutex;
    std::condition_variable m_wake;
    std::optional<Pending> m_pending;
    Snapshot m_snapshot;
    std::shared_ptr<const render::SceneView> m_view;
    std::vector<std::shared_ptr<const sim::TetMesh>> m_bodyMeshes;    ///< of the scene shown
    std::vector<std::shared_ptr<const sim::TriMesh>> m_surfaceMeshes; ///< of the scene shown
    std::thread m_thread;
    std::thread m_sampler; ///< error sampling, at a lower priority than the preview
    std::mutex m_sampleMutex;
    std::condition_variable m_sampleWake;
    std::optional<SampleJob> m_sampleJob;
    bool m_sampling = false;
    std::atomic<bool> m_stop{false};
    std::atomic<int> m_accuracyEvery{60};
    std::atomic<bool> m_realTime{true};
    std::atomic<bool> m_paused{false};
    std::atomic<uint64_t> m_revision{0};
    std::atomic<int64_t> m_lastSubmitNs{0}; ///< steady clock, at the last submit()
    uint64_t m_nextSample = 0;              ///< worker only: first frame of the next sample
    uint64_t m_serial = 0;
};

/// What the preview's physics cost says of real time: the mean of the last `window` frames against
/// the scene's frame time (16.7 ms at 60 Hz). The preview runs one solver thread beside the UI, so
/// this is what a trainee's machine of this class would see at worst.
struct RealTimeEstimate {
    int frames = 0;      ///< frames averaged (0: no estimate yet)
    double meanMs = 0;   ///< physics ms per frame
    double budgetMs = 0; ///< the frame time, ms
    double factor = 0;   ///< budget / mean: 1 keeps real time exactly
    bool slower() const { return frames > 0 && factor < 1; }
};
/// `frameDt` in s; at least `minFrames` of `frameMs` are needed (else frames = 0).
RealTimeEstimate estimateRealTime(const std::deque<double>& frameMs, double frameDt, size_t window = 60,
                                  size_t minFrames = 10);

} // namespace viscera::studio
