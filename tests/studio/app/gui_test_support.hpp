#pragma once
// Shared by the studio GUI tests: one QApplication for the process (created on first use, on
// the display the test step provides: Xvfb with Mesa), synthetic mouse events sent to the real
// widgets, waiting with the event loop running, and a scratch copy of a sample project.
#include "app/studio_app.hpp"
#include "support/scratch_dir.hpp"

#include <QApplication>
#include <QCoreApplication>
#include <QElapsedTimer>
#include <QMouseEvent>
#include <QScreen>
#include <QStandardPaths>
#include <QTest>
#include <QWidget>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

namespace viscera::test {

inline QApplication& guiApp() {
    static int argc = 1;
    static char name[] = "viscera-studio-gui-test";
    static char* argv[] = {name, nullptr};
    static QApplication* app = [] {
        QStandardPaths::setTestModeEnabled(true); // QSettings go to a test location
        studio::setStudioSurfaceFormat();
        auto* a = new QApplication(argc, argv);
        QCoreApplication::setOrganizationName("VisceraTest");
        QCoreApplication::setApplicationName("StudioGuiTest");
        return a;
    }();
    return *app;
}

/// Runs the event loop until `done` holds or `ms` pass; returns `done()`.
inline bool waitFor(const std::function<bool()>& done, int ms) {
    QElapsedTimer t;
    t.start();
    while (!done()) {
        if (t.elapsed() > ms) return false;
        QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
        QTest::qWait(5);
    }
    return true;
}

/// With VISCERA_GUI_SHOTS set to a folder: the whole screen (the GL viewport included) saved there
/// as <name>.png, for looking at what a test drove. Otherwise nothing.
inline void saveShot(const char* name) {
    const char* dir = std::getenv("VISCERA_GUI_SHOTS");
    if (!dir || !*dir) return;
    QTest::qWait(200); // the viewport's next frame
    if (QScreen* s = QGuiApplication::primaryScreen())
        s->grabWindow(0).save(QString::fromStdString((std::filesystem::path(dir) / name).string() + ".png"));
}

inline void sendMouse(QWidget* w, QEvent::Type type, QPointF pos, Qt::MouseButton button, Qt::MouseButtons buttons,
                      Qt::KeyboardModifiers mods = Qt::NoModifier) {
    QMouseEvent e(type, pos, w->mapToGlobal(pos), button, buttons, mods);
    QApplication::sendEvent(w, &e);
}

/// A press at `from`, `steps` moves along the line to `to`, a release there.
inline void drag(QWidget* w, QPointF from, QPointF to, int steps, Qt::MouseButton button = Qt::LeftButton,
                 Qt::KeyboardModifiers mods = Qt::NoModifier) {
    sendMouse(w, QEvent::MouseButtonPress, from, button, button, mods);
    for (int i = 1; i <= steps; ++i) {
        const double t = static_cast<double>(i) / steps;
        sendMouse(w, QEvent::MouseMove, from + t * (to - from), Qt::NoButton, button, mods);
    }
    sendMouse(w, QEvent::MouseButtonRelease, to, button, Qt::NoButton, mods);
}

inline void click(QWidget* w, QPointF pos, Qt::KeyboardModifiers mods = Qt::NoModifier) {
    sendMouse(w, QEvent::MouseButtonPress, pos, Qt::LeftButton, Qt::LeftButton, mods);
    sendMouse(w, QEvent::MouseButtonRelease, pos, Qt::LeftButton, Qt::NoButton, mods);
}

/// A copy of projects/<name> in a scratch folder (the tests edit and save it).
inline std::filesystem::path copySample(const Scratch& s, const std::string& name) {
    const std::filesystem::path to = s.dir / name;
    std::filesystem::copy(std::filesystem::path(VISCERA_SOURCE_DIR) / "projects" / name, to,
                          std::filesystem::copy_options::recursive);
    return to;
}

} // namespace viscera::test
