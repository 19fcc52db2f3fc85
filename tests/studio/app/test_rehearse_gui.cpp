// Rehearse in the studio [issue 57 item 3], driven through the Rehearse dock under Xvfb: the rectum
// rehearsed with its committed replay gives the player's verdict (PASS, both clips on target) while
// the viewport shows the session; the session kept as a reference replay is a valid trajectory file
// that, replayed again, passes too; the keyboard in the viewport drives the left master (the
// recorded device moved as the keys said); the console simulator streaming over UDP drives it
// on the wall clock; a malformed device spec is refused naming the rule.
#include "app/rehearsal.hpp"
#include "app/rehearse_panel.hpp"
#include "app/viewport.hpp"
#include "haptics/trajectory.hpp"
#include "window_fixture.hpp"

#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QProcess>
#include <QPushButton>
#include <QSignalSpy>
#include <QSpinBox>
#include <QWindow>

#include <gtest/gtest.h>

#include <fstream>

using namespace viscera;
namespace fs = std::filesystem;

namespace {

struct RehearseFixture : test::MainWindowFixture {
    RehearseFixture() : MainWindowFixture("viscera-rehearse-gui") {}
    studio::RehearsePanel* panel = nullptr;
    fs::path dir;

    void SetUp() override {
        MainWindowFixture::SetUp();
        dir = open("rectum");
        panel = w->rehearsePanel();
        ASSERT_NE(panel, nullptr);
        panel->rehearsal()->exportRunner().setProgram(VISCERA_STUDIO_EXE);
        auto* dock = w->findChild<QDockWidget*>("rehearseDock");
        ASSERT_NE(dock, nullptr);
        dock->raise();
        QCoreApplication::processEvents();
    }
    /// Types `spec` into the device field (its text selected first, as a user replaces it).
    void typeDevice(const QString& spec) {
        QComboBox* box = panel->deviceBox();
        box->setFocus();
        QTest::keyClick(box->lineEdit(), Qt::Key_A, Qt::ControlModifier);
        QTest::keyClicks(box->lineEdit(), spec);
        ASSERT_EQ(box->currentText(), spec);
    }
    /// Clicks Rehearse and waits for the session to end (the export, the load and the run).
    bool rehearse(int timeoutMs) {
        QSignalSpy done(panel->rehearsal(), &studio::Rehearsal::finished);
        QTest::mouseClick(panel->startButton(), Qt::LeftButton);
        return test::waitFor([&] { return !done.isEmpty(); }, timeoutMs);
    }
    void keyOnCanvas(bool press, Qt::Key key) {
        if (QWindow* c = w->viewport()->canvasWindow())
            press ? QTest::keyPress(c, key) : QTest::keyRelease(c, key);
        else
            press ? QTest::keyPress(w->viewport()->canvasWidget(), key)
                  : QTest::keyRelease(w->viewport()->canvasWidget(), key);
    }
    void shoot(const char* name) {
        const char* shots = std::getenv("VISCERA_GUI_SHOTS");
        if (!shots || !*shots) return;
        w->viewport()->grabFramebuffer().save(QString(shots) + "/" + name + "_viewport.png");
        test::saveShot(name);
    }
};

} // namespace

TEST_F(RehearseFixture, TheReplayRehearsedGivesThePlayersVerdictAndTheKeptReplayPassesToo) {
    const QString replay = QString::fromStdString((dir / "replays" / "dissection.csv").string());
    ASSERT_GE(panel->deviceBox()->findText("replay:" + replay), 0) << "the project's replays are offered";
    typeDevice("replay:" + replay);
    const int meshesBefore = w->viewport()->meshCount();
    QSignalSpy frames(panel->rehearsal(), &studio::Rehearsal::frame);
    QSignalSpy done(panel->rehearsal(), &studio::Rehearsal::finished);
    QTest::mouseClick(panel->startButton(), Qt::LeftButton);
    EXPECT_FALSE(panel->startButton()->isEnabled()) << "one rehearsal at a time";
    EXPECT_TRUE(panel->stopButton()->isEnabled());
    // mid-session: the viewport draws the session (the case's meshes and the instruments')
    ASSERT_TRUE(test::waitFor([&] { return panel->rehearsal()->framesDone() > 150 || !done.isEmpty(); }, 120000));
    ASSERT_TRUE(done.isEmpty()) << panel->status()->text().toStdString();
    EXPECT_GT(frames.count(), 3);
    EXPECT_GT(w->viewport()->meshCount(), meshesBefore) << "the instruments are drawn";
    EXPECT_TRUE(w->preview()->paused()) << "the preview rests while the session runs";
    shoot("rehearse_dissection_running");
    ASSERT_TRUE(test::waitFor([&] { return !done.isEmpty(); }, 120000));
    const studio::Rehearsal::Outcome& o = panel->rehearsal()->outcome();
    ASSERT_TRUE(o.ran) << o.error.toStdString();
    EXPECT_TRUE(o.judged);
    EXPECT_TRUE(o.passed) << o.summary.join('\n').toStdString();
    const double length = haptics::Trajectory::load(replay.toStdString()).duration();
    EXPECT_EQ(o.frames, player::replayFrames(length, o.frameDt)) << "a replay runs its length";
    EXPECT_TRUE(panel->verdict()->text().startsWith("PASS")) << panel->verdict()->text().toStdString();
    EXPECT_TRUE(panel->summary()->toPlainText().contains("clips_on_target 2 count (limit ≥ 2) pass"));
    EXPECT_FALSE(w->preview()->paused()) << "the preview comes back";
    const double session = o.frames * o.frameDt; // s: the replay's length and the 0.5 s after it
    shoot("rehearse_dissection_verdict");

    // Keep it: a refused name first, then a good one; the kept file replays to a pass.
    panel->replayName()->setText("bad name!");
    QTest::mouseClick(panel->keepButton(), Qt::LeftButton);
    EXPECT_TRUE(panel->status()->text().contains("use 1 to 64 letters")) << panel->status()->text().toStdString();
    EXPECT_FALSE(fs::exists(dir / "replays" / "bad name!.csv"));
    panel->replayName()->setText("kept");
    done.clear();
    QTest::mouseClick(panel->keepButton(), Qt::LeftButton);
    const fs::path kept = dir / "replays" / "kept.csv";
    ASSERT_TRUE(fs::exists(kept)) << panel->status()->text().toStdString();
    const haptics::Trajectory back = haptics::Trajectory::load(kept);
    EXPECT_EQ(back.arms(), 2);
    EXPECT_NEAR(back.duration(), session, 0.03) << "the whole session, not a part";
    EXPECT_EQ(panel->deviceBox()->currentText(), "replay:" + QString::fromStdString(kept.string()));
    ASSERT_TRUE(test::waitFor([&] { return !done.isEmpty(); }, 120000));
    EXPECT_TRUE(panel->verdict()->text().startsWith("The kept replay: PASS")) << panel->verdict()->text().toStdString();
    // the same name again: refused, the file untouched
    const auto stamp = fs::last_write_time(kept);
    QTest::mouseClick(panel->keepButton(), Qt::LeftButton);
    EXPECT_TRUE(panel->status()->text().contains("exists; choose another name"))
        << panel->status()->text().toStdString();
    EXPECT_EQ(fs::last_write_time(kept), stamp);
}

TEST_F(RehearseFixture, TheKeyboardInTheViewportDrivesTheLeftMasterAndStopEndsTheSession) {
    typeDevice("keyboard");
    QSignalSpy started(panel->rehearsal(), &studio::Rehearsal::started);
    QSignalSpy done(panel->rehearsal(), &studio::Rehearsal::finished);
    QTest::mouseClick(panel->startButton(), Qt::LeftButton);
    ASSERT_TRUE(test::waitFor([&] { return !started.isEmpty() || !done.isEmpty(); }, 60000));
    ASSERT_TRUE(done.isEmpty()) << panel->status()->text().toStdString();
    ASSERT_TRUE(test::waitFor([&] { return panel->rehearsal()->framesDone() > 5; }, 30000));
    keyOnCanvas(true, Qt::Key_Down); // −y at 5 cm/s
    QTest::qWait(600);
    keyOnCanvas(false, Qt::Key_Down);
    keyOnCanvas(true, Qt::Key_PageDown); // −z
    QTest::qWait(400);
    keyOnCanvas(false, Qt::Key_PageDown);
    keyOnCanvas(true, Qt::Key_G); // the grip closed, the cut pedal held
    keyOnCanvas(true, Qt::Key_E);
    QTest::qWait(300);
    keyOnCanvas(false, Qt::Key_G);
    keyOnCanvas(false, Qt::Key_E);
    QTest::qWait(200);
    shoot("rehearse_keyboard");
    QTest::mouseClick(panel->stopButton(), Qt::LeftButton);
    ASSERT_TRUE(test::waitFor([&] { return !done.isEmpty(); }, 30000));
    const haptics::Trajectory& rec = panel->rehearsal()->recorded();
    ASSERT_GE(rec.arms(), 1);
    const haptics::Vec3 end = rec.samples(0).back().pose.position, start = rec.samples(0).front().pose.position;
    EXPECT_LT(end.y() - start.y(), -0.015) << "Down held 0.6 s at 5 cm/s";
    EXPECT_LT(end.z() - start.z(), -0.008) << "Page Down held 0.4 s";
    EXPECT_NEAR(end.x(), start.x(), 1e-6) << "nothing moved x";
    bool closed = false, cutting = false;
    for (const haptics::TrajectorySample& x : rec.samples(0)) {
        closed = closed || x.grip == 0.0;
        cutting = cutting || (x.pedals & haptics::kPedalEnergyCut);
    }
    EXPECT_TRUE(closed) << "G closed the grip";
    EXPECT_TRUE(cutting) << "E held the cut pedal";
    EXPECT_EQ(rec.samples(0).back().grip, haptics::KeyboardDevice::kOpenGrip) << "open again";
    const studio::Rehearsal::Outcome& o = panel->rehearsal()->outcome();
    ASSERT_TRUE(o.ran) << o.error.toStdString();
    EXPECT_TRUE(o.judged);
    EXPECT_FALSE(o.passed) << "a few keys do not do the task";
    EXPECT_TRUE(panel->verdict()->text().startsWith("FAIL (")) << panel->verdict()->text().toStdString();
    // a failed session is no reference replay: Keep says why and writes nothing
    panel->replayName()->setText("failing");
    QTest::mouseClick(panel->keepButton(), Qt::LeftButton);
    EXPECT_TRUE(panel->status()->text().contains("a reference replay must pass its case"))
        << panel->status()->text().toStdString();
    EXPECT_FALSE(fs::exists(dir / "replays" / "failing.csv"));
}

TEST_F(RehearseFixture, TheConsoleSimulatorDrivesTheSessionOverItsPairedLink) {
    const fs::path key = scratch.dir / "pairing.key", portFile = scratch.dir / "port";
    ASSERT_EQ(QProcess::execute(VISCERA_CONSOLE_SIM_EXE, {"--make-pairing-key", QString::fromStdString(key.string())}),
              0);
    QProcess console;
    console.start(VISCERA_CONSOLE_SIM_EXE,
                  {"--listen", "127.0.0.1:0", "--port-file", QString::fromStdString(portFile.string()), "--script",
                   "bimanual", "--duration", "30", "--pairing-key", QString::fromStdString(key.string()),
                   "--wait-player", "60", "--until-player-stops"});
    ASSERT_TRUE(console.waitForStarted(10000));
    ASSERT_TRUE(test::waitFor([&] { return fs::exists(portFile) && fs::file_size(portFile) > 0; }, 10000));
    std::ifstream in(portFile);
    std::string port;
    in >> port;
    typeDevice(QString::fromStdString("console:127.0.0.1:" + port));
    panel->findChild<QLineEdit*>("rehearsePairingKey")->setText(QString::fromStdString(key.string()));
    panel->framesBox()->setValue(120); // 2 s
    ASSERT_TRUE(rehearse(90000)) << panel->status()->text().toStdString();
    console.kill(); // the console streams until told: its part is done
    console.waitForFinished(5000);
    const studio::Rehearsal::Outcome& o = panel->rehearsal()->outcome();
    ASSERT_TRUE(o.ran) << o.error.toStdString();
    EXPECT_EQ(o.frames, 120);
    const haptics::Trajectory& rec = panel->rehearsal()->recorded();
    ASSERT_EQ(rec.arms(), 2) << "both masters of the console";
    double moved = 0;
    for (const haptics::TrajectorySample& s : rec.samples(0))
        moved = std::max(moved, (s.pose.position - rec.samples(0).front().pose.position).norm());
    EXPECT_GT(moved, 0.01) << "the bimanual script presses arm 0 down";
    EXPECT_GT(rec.duration(), 1.5) << "two seconds of the wall clock recorded";
}

TEST_F(RehearseFixture, AMalformedDeviceIsRefusedNamingTheRuleAndNothingRuns) {
    typeDevice("joystick:1");
    QTest::mouseClick(panel->startButton(), Qt::LeftButton);
    EXPECT_EQ(panel->rehearsal()->state(), studio::Rehearsal::State::Idle);
    EXPECT_TRUE(panel->status()->text().contains("unknown device backend")) << panel->status()->text().toStdString();
    EXPECT_TRUE(panel->startButton()->isEnabled());
    EXPECT_FALSE(panel->keepButton()->isEnabled()) << "nothing recorded";
    panel->replayName()->setText("nothing");
    EXPECT_FALSE(panel->keep()) << "nothing recorded: nothing kept";
    EXPECT_FALSE(fs::exists(dir / "replays" / "nothing.csv"));
    // Stop while the case exports: nothing runs, the window is as before
    typeDevice("replay:" + QString::fromStdString((dir / "replays" / "dissection.csv").string()));
    QSignalSpy stopped(panel->rehearsal(), &studio::Rehearsal::finished);
    QTest::mouseClick(panel->startButton(), Qt::LeftButton);
    ASSERT_EQ(panel->rehearsal()->state(), studio::Rehearsal::State::Exporting);
    QTest::mouseClick(panel->stopButton(), Qt::LeftButton);
    ASSERT_TRUE(test::waitFor([&] { return !stopped.isEmpty(); }, 10000));
    EXPECT_EQ(panel->rehearsal()->state(), studio::Rehearsal::State::Idle);
    EXPECT_TRUE(panel->status()->text().contains("stopped during the export")) << panel->status()->text().toStdString();
    EXPECT_TRUE(panel->verdict()->text().startsWith("Not run"));
    EXPECT_TRUE(panel->startButton()->isEnabled());
    EXPECT_FALSE(w->preview()->paused()) << "the preview came back";
    typeDevice("replay:" + QString::fromStdString((dir / "replays" / "missing.csv").string()));
    ASSERT_TRUE(rehearse(60000));
    EXPECT_FALSE(panel->rehearsal()->outcome().ran);
    EXPECT_TRUE(panel->verdict()->text().startsWith("Not run"));
    EXPECT_TRUE(panel->summary()->toPlainText().contains("missing.csv"))
        << panel->summary()->toPlainText().toStdString();
}
