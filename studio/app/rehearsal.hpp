#pragma once
/// Rehearse in the studio (issue 57 item 3): the case run as the player runs it, from the model as
/// it is in the editor, so the artist sees whether the task can be done from these ports before
/// exporting.
///
/// start() exports the model to a private temporary folder (ExportRunner: the same export as
/// File → Export, unsigned, since the package never leaves the studio), loads the package as the
/// player does (player::loadCase, unsigned allowed) and runs a session (player::runSession) on a
/// worker thread with the device chosen by its player spec (haptics::parseDeviceSpec, the one
/// rule): the keyboard and mouse in the viewport and the console run on the wall clock; a
/// replay or a `scripted:` motion runs in lockstep with the physics, as `viscera-player run
/// --headless` and the case's replay tests run it, so its verdict is theirs. The device is
/// recorded (haptics::RecordingDevice) for keepReplay().
///
/// While the session runs, live() holds its geometry (player::LiveScene, the trainee window's
/// rule), refreshed about 30 times a second on the UI thread (frame()). When it ends (its frames
/// done, or stop()), outcome() holds the verdict and the assessment's summary lines as the
/// player prints them.
#include "app/export_runner.hpp"
#include "haptics/keyboard_device.hpp"
#include "haptics/trajectory.hpp"
#include "project/project.hpp"
#include "runtime/live_scene.hpp"

#include <QObject>
#include <QString>
#include <QStringList>
#include <QTemporaryDir>
#include <QTimer>

#include <memory>

namespace viscera::studio {

class Rehearsal : public QObject {
    Q_OBJECT
public:
    enum class State { Idle, Exporting, Running };
    struct Options {
        QString device = QStringLiteral("keyboard"); ///< a player --device spec
        /// Frames to run; 0: a replay runs its length and 0.5 s more, a scripted motion 300
        /// frames, the keyboard and the console until stop().
        int frames = 0;
        QString pairingKey; ///< console: the pairing key file
    };
    struct Outcome {
        bool ran = false;    ///< a session ran (false: the export, the load or the device failed)
        bool judged = false; ///< the case has an assessment (a verdict)
        bool passed = false;
        QString verdict;            ///< "PASS", "FAIL (clips_on_target)" or "no assessment"
        QStringList summary;        ///< the assessment's lines as the player prints them
        QString device;             ///< the spec it ran with
        int frames = 0;             ///< frames simulated
        double physicsMs = 0;       ///< mean physics time per frame
        double frameDt = 0;         ///< s
        QString error;              ///< why it did not run, or the session's first error
        bool recordingFull = false; ///< the session outran the device's recording
    };

    explicit Rehearsal(QObject* parent = nullptr);
    ~Rehearsal() override;

    ExportRunner& exportRunner() { return m_export; }
    /// Starts rehearsing `project` (its files resolve against project.dir). False and `why` (one
    /// line naming the field or file and the rule) when it cannot start: a malformed device spec,
    /// a rehearsal already running, an export that cannot start.
    bool start(const Project& project, const Options& options, QString* why);
    /// Ends the session (its outcome is what ran so far) or cancels the export.
    void stop();
    State state() const { return m_state; }
    bool active() const { return m_state != State::Idle; }
    /// The keyboard device while a keyboard rehearsal runs (the viewport's keys and mouse go to
    /// it), else null.
    haptics::KeyboardDevice* keyboard() const;
    /// The running session's scene (UI thread; null before the session starts).
    const player::LiveScene* live() const { return m_scene.get(); }
    /// Frames the session has done (updated with frame()).
    int framesDone() const { return m_framesDone; }
    const Outcome& outcome() const { return m_outcome; }
    /// What the device did in the last session (empty before one ran).
    const haptics::Trajectory& recorded() const { return m_recorded; }

    /// Writes the last session's device as `<project folder>/replays/<name>.csv` (never over a
    /// file: written beside it, then linked in) and returns its path; empty and `why` when the name
    /// is not [A-Za-z0-9_-]{1,64}, the file exists, nothing was recorded, the session did not pass
    /// (a reference replay is a test that must pass: test_case_replays), outran the recording, or
    /// the folder cannot be written.
    QString keepReplay(const std::filesystem::path& projectDir, const QString& name, QString* why) const;

signals:
    void stateChanged(Rehearsal::State state);
    void progress(const QString& stage);
    /// The session started: live() is its scene at rest.
    void started();
    /// New geometry is in live() (about 30 per second while the session runs).
    void frame();
    /// The session ended (or failed before it ran): outcome() says how.
    void finished(bool ok);

private:
    struct Run;
    void onExported(bool ok, const QString& message);
    void onStarted();
    void onDone();
    /// The session's latest geometry into live() when a new frame came (`always`: in any case).
    void pollLive(bool always = false);
    void fail(const QString& why);
    void setState(State s);

    ExportRunner m_export;
    std::unique_ptr<QTemporaryDir> m_tmp;
    Options m_options;
    State m_state = State::Idle;
    std::unique_ptr<Run> m_run;
    std::unique_ptr<player::LiveScene> m_scene;
    QTimer m_poll;
    int m_framesDone = 0;
    int m_appliedFrames = -1; ///< the frames the scene shown was made after
    bool m_stopAsked = false;
    Outcome m_outcome;
    haptics::Trajectory m_recorded;
};

} // namespace viscera::studio
