#include "app/rehearsal.hpp"

#include "haptics/device_spec.hpp"
#include "haptics/recording_device.hpp"
#include "haptics/replay_device.hpp"
#include "render/tool_meshes.hpp"
#include "runtime/report.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <QDir>
#include <QRegularExpression>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <thread>

#include <unistd.h>

namespace viscera::studio {

/// One session: its device, the worker thread that loads the case and runs it, and what the
/// worker hands back (the scene at rest, then the result).
struct Rehearsal::Run {
    std::thread thread;
    std::atomic<bool> stop{false};
    player::LiveView live;
    std::unique_ptr<haptics::Device> device;
    std::unique_ptr<haptics::RecordingDevice> recorder;
    haptics::KeyboardDevice* keyboard = nullptr;
    std::string spec;
    haptics::DeviceSpec::Kind kind = haptics::DeviceSpec::Kind::Keyboard;
    std::mutex handover;                      ///< guards scene (worker → UI thread)
    std::unique_ptr<player::LiveScene> scene; ///< the case at rest, until the UI thread takes it
    std::atomic<int> framesDone{0};
    // Written by the worker before it posts onDone:
    player::SessionResult result;
    bool ran = false;
    std::string error;

    ~Run() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
};

Rehearsal::Rehearsal(QObject* parent) : QObject(parent) {
    connect(&m_export, &ExportRunner::progress, this, [this](int done, int total, const QString& stage) {
        emit progress(tr("exporting %1/%2: %3").arg(done).arg(total).arg(stage));
    });
    connect(&m_export, &ExportRunner::finished, this, &Rehearsal::onExported);
    m_poll.setInterval(33);
    connect(&m_poll, &QTimer::timeout, this, [this] { pollLive(); });
}

Rehearsal::~Rehearsal() {
    // Nothing is said any more: the window that listens may be half gone (the cancel below
    // reports at once).
    blockSignals(true);
    m_export.disconnect(this);
    if (m_export.running()) m_export.cancel();
    m_run.reset(); // stops and joins the worker before the members it posts to go
}

haptics::KeyboardDevice* Rehearsal::keyboard() const {
    return m_state == State::Running && m_run ? m_run->keyboard : nullptr;
}

void Rehearsal::setState(State s) {
    if (s == m_state) return;
    m_state = s;
    emit stateChanged(s);
}

bool Rehearsal::start(const Project& project, const Options& options, QString* why) {
    auto refuse = [&](const QString& w) {
        if (why) *why = w;
        return false;
    };
    if (active()) return refuse(tr("a rehearsal is running: stop it first"));
    try {
        haptics::parseDeviceSpec(options.device.trimmed().toStdString());
    } catch (const std::exception& e) {
        return refuse(QString::fromStdString(e.what()));
    }
    if (options.frames < 0 || options.frames > 10'000'000)
        return refuse(tr("frames %1: must be in [0, 10000000] (0: the device's length)").arg(options.frames));
    m_tmp = std::make_unique<QTemporaryDir>(QDir::temp().filePath("viscera-rehearsal-XXXXXX"));
    if (!m_tmp->isValid())
        return refuse(tr("%1: no temporary folder for the rehearsal's package").arg(QDir::tempPath()));
    m_options = options;
    m_options.device = options.device.trimmed();
    m_outcome = Outcome{};
    m_outcome.device = m_options.device;
    m_recorded = haptics::Trajectory{}; // a session that does not run leaves nothing to keep
    m_framesDone = 0;
    m_stopAsked = false;
    setState(State::Exporting);    // before the start: a child that fails at once reports into this state
    ExportSigning unsignedPackage; // never leaves the studio: the session allows it
    if (!m_export.start(project, m_tmp->filePath("rehearsal.vcase"), unsignedPackage, why)) {
        setState(State::Idle);
        return false;
    }
    if (m_state == State::Exporting) emit progress(tr("exporting the case"));
    return true;
}

void Rehearsal::stop() {
    m_stopAsked = m_state != State::Idle;
    if (m_state == State::Exporting)
        m_export.cancel(); // finished(false, "cancelled") follows
    else if (m_state == State::Running && m_run)
        m_run->stop = true;
}

void Rehearsal::fail(const QString& why) {
    m_outcome.ran = false;
    m_outcome.error = why;
    m_outcome.verdict = tr("not run");
    m_run.reset();
    m_scene.reset();
    setState(State::Idle);
    emit progress(why);
    emit finished(false);
}

void Rehearsal::onExported(bool ok, const QString& message) {
    if (m_state != State::Exporting) return;
    if (!ok) return fail(m_stopAsked ? tr("rehearsal stopped during the export") : tr("export: %1").arg(message));
    auto run = std::make_unique<Run>();
    run->spec = m_options.device.toStdString();
    try {
        const haptics::DeviceSpec spec = haptics::parseDeviceSpec(run->spec);
        haptics::DeviceOpenOptions o;
        o.pairingKeyFile = m_options.pairingKey.toStdString();
        run->kind = spec.kind;
        run->device = haptics::openDevice(spec, o);
        run->keyboard = dynamic_cast<haptics::KeyboardDevice*>(run->device.get());
        run->recorder = std::make_unique<haptics::RecordingDevice>(*run->device);
    } catch (const std::exception& e) {
        return fail(QString::fromStdString(e.what()));
    }
    double replayLength = -1;
    if (auto* replay = dynamic_cast<haptics::ReplayDevice*>(run->device.get()))
        replayLength = replay->trajectory().duration();
    const std::string casePath = m_tmp->filePath("rehearsal.vcase").toStdString();
    const int frames = m_options.frames;
    Run* r = run.get();
    r->thread = std::thread([this, r, casePath, frames, replayLength] {
        try {
            vcase::TrustPolicy trust; // the studio's own package, made a moment ago: unsigned is fine
            trust.allowUnsigned = true;
            trust.now =
                std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch())
                    .count();
            player::LoadedCase loaded = player::loadCase(casePath, trust);
            if (r->stop) throw std::runtime_error("rehearsal stopped while the case loaded");
            auto scene = std::make_unique<player::LiveScene>(loaded);
            scene->addTools(render::toolPoses(*loaded.world));
            {
                std::lock_guard<std::mutex> lock(r->handover);
                r->scene = std::move(scene);
            }
            QMetaObject::invokeMethod(this, &Rehearsal::onStarted, Qt::QueuedConnection);
            player::RunOptions o;
            const bool wallClock = r->device->capabilities().realtime;
            o.frames = frames > 0          ? frames
                       : replayLength >= 0 ? player::replayFrames(replayLength, loaded.world->dt())
                       : r->kind == haptics::DeviceSpec::Kind::Scripted ? 300
                                                                        : 0;
            o.device = r->recorder.get();
            o.deviceSpec = r->spec;
            o.realtime = wallClock;
            o.stop = &r->stop;
            o.live = &r->live;
            o.progress = [r](int done, int) { r->framesDone.store(done, std::memory_order_relaxed); };
            r->result = player::runSession(loaded, o);
            r->ran = true;
        } catch (const std::exception& e) {
            r->error = e.what();
        }
        QMetaObject::invokeMethod(this, &Rehearsal::onDone, Qt::QueuedConnection);
    });
    m_run = std::move(run);
    setState(State::Running);
    emit progress(tr("loading the case"));
}

void Rehearsal::onStarted() {
    if (!m_run) return;
    {
        std::lock_guard<std::mutex> lock(m_run->handover);
        m_scene = std::move(m_run->scene);
    }
    if (!m_scene) return;
    m_appliedFrames = -1;
    m_poll.start();
    emit progress(m_run->keyboard
                      ? tr("running: arrows, Page Up/Down and a drag move the tool; G grip, E cut pedal, B next "
                           "instrument, Space clutch")
                      : tr("running %1").arg(m_options.device));
    emit started();
}

void Rehearsal::pollLive(bool always) {
    if (!m_run || !m_scene) return;
    m_framesDone = m_run->framesDone.load(std::memory_order_relaxed);
    if (!always && m_framesDone == m_appliedFrames) return; // no new frame: the viewport keeps its meshes
    player::LiveGeometry g;
    {
        std::lock_guard<std::mutex> lock(m_run->live.mutex);
        g = m_run->live.geometry;
    }
    if (!m_scene->apply(g)) return;
    m_appliedFrames = m_framesDone;
    emit frame();
}

void Rehearsal::onDone() {
    if (!m_run) return;
    m_poll.stop();
    if (m_run->thread.joinable()) m_run->thread.join();
    pollLive(true); // the last frame
    Run& r = *m_run;
    m_recorded = r.recorder ? r.recorder->trajectory() : haptics::Trajectory{};
    if (!r.ran) return fail(QString::fromStdString(r.error));
    const player::SessionResult& s = r.result;
    Outcome& o = m_outcome;
    o.ran = true;
    o.frames = static_cast<int>(s.frames.size());
    o.frameDt = s.frameDt;
    double sum = 0;
    for (const sim::FrameRecord& f : s.frames)
        sum += f.stepMs;
    o.physicsMs = s.frames.empty() ? 0 : sum / static_cast<double>(s.frames.size());
    o.judged = s.assessment.judged;
    o.passed = s.ok() && s.assessment.judged && s.assessment.passed;
    o.summary = QString::fromStdString(player::assessmentSummary(s.assessment)).split('\n', Qt::SkipEmptyParts);
    o.verdict = QString::fromStdString(player::verdictText(s.assessment));
    o.recordingFull = r.recorder && r.recorder->full();
    if (!s.errors.empty())
        o.error = QString::fromStdString(s.errors.front());
    else if (!s.invariants.allFinite)
        o.error = tr("the session's state was not finite");
    if (!o.error.isEmpty()) o.verdict = tr("FAIL (the session failed: %1)").arg(o.error);
    m_framesDone = o.frames;
    m_run.reset();
    setState(State::Idle);
    emit progress(
        tr("%1 frames, physics %2 ms per frame: %3").arg(o.frames).arg(o.physicsMs, 0, 'f', 1).arg(o.verdict));
    emit finished(o.error.isEmpty());
}

QString Rehearsal::keepReplay(const std::filesystem::path& projectDir, const QString& name, QString* why) const {
    auto refuse = [&](const QString& w) {
        if (why) *why = w;
        return QString();
    };
    static const QRegularExpression rule("^[A-Za-z0-9_-]{1,64}$");
    if (!rule.match(name).hasMatch())
        return refuse(tr("replay name '%1': use 1 to 64 letters, digits, '-' or '_'").arg(name));
    if (m_recorded.arms() == 0) return refuse(tr("no session recorded yet: rehearse first"));
    if (m_outcome.recordingFull)
        return refuse(tr("the session ran longer than the recording holds (%1 s): rehearse a shorter one")
                          .arg(m_recorded.duration(), 0, 'f', 0));
    if (!m_outcome.ran || !m_outcome.error.isEmpty() || (m_outcome.judged && !m_outcome.passed))
        return refuse(tr("a reference replay must pass its case: this session's verdict is %1").arg(m_outcome.verdict));
    const std::filesystem::path dir = projectDir / "replays";
    const std::filesystem::path file = dir / (name.toStdString() + ".csv");
    const QString shown = QString::fromStdString(file.string());
    std::error_code ec;
    if (std::filesystem::exists(file, ec)) return refuse(tr("%1: exists; choose another name").arg(shown));
    try {
        std::filesystem::create_directories(dir);
        std::string text = "# viscera-trajectory 1\n# Recorded in the studio's rehearsal with " +
                           m_outcome.device.toStdString() + ": " + m_outcome.verdict.toStdString() + "\n";
        const std::string body = m_recorded.format();
        text += body.substr(body.find('\n') + 1); // format() starts with the magic line
        // Written whole beside it, then linked in: link() refuses a name that came meanwhile.
        const std::filesystem::path part = dir / ("." + name.toStdString() + ".csv.part");
        writeFileAtomic(part, text);
        const int linked = ::link(part.c_str(), file.c_str());
        const int err = errno;
        std::filesystem::remove(part, ec);
        if (linked != 0 && err == EEXIST) return refuse(tr("%1: exists; choose another name").arg(shown));
        if (linked != 0)
            return refuse(tr("%1: cannot be written: %2").arg(shown, QString::fromLocal8Bit(strerror(err))));
    } catch (const std::exception& e) {
        return refuse(QString::fromStdString(e.what()));
    }
    return shown;
}

} // namespace viscera::studio
