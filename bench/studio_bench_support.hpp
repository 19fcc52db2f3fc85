#pragma once
// What the studio benches share: the event loop run as in a session, and synthetic mouse events.
#include <QApplication>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QMouseEvent>
#include <QTimer>
#include <QWidget>

#include <cstdio>
#include <functional>
#include <string>

namespace viscera::bench {

/// Runs the event loop (sleeping while idle, as in a session) until `done` or `ms` pass.
inline bool waitFor(const std::function<bool()>& done, int ms) {
    QElapsedTimer t;
    t.start();
    while (!done() && t.elapsed() < ms) {
        QEventLoop loop;
        QTimer::singleShot(20, &loop, &QEventLoop::quit);
        loop.exec();
    }
    return done();
}

inline void send(QWidget* w, QEvent::Type type, QPointF pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    QMouseEvent e(type, pos, w->mapToGlobal(pos), button, buttons, Qt::NoModifier);
    QApplication::sendEvent(w, &e);
}

/// The start of the paint benches: a main window of 1600 × 1000 with the sample project
/// `project` open, its preview built and body `body` selected. Returns the body's index, or -1
/// with the reason on stderr. `Window` is studio::MainWindow (kept a template so the benches that
/// do not open a project need not include it).
template <class Window> int openSampleBody(Window& w, const std::string& project, const std::string& body) {
    w.setConfirmDiscard(false);
    w.resize(1600, 1000);
    w.show();
    if (!w.openProject(QString::fromStdString(std::string(VISCERA_SOURCE_DIR) + "/projects/" + project))) return -1;
    int index = -1;
    for (size_t i = 0; i < w.document()->project().bodies.size(); ++i)
        if (w.document()->project().bodies[i].scene.name == body) index = static_cast<int>(i);
    if (index < 0) {
        std::fprintf(stderr, "no body '%s' in %s\n", body.c_str(), project.c_str());
        return -1;
    }
    std::printf("waiting for the preview (meshing %s)...\n", project.c_str());
    if (!waitFor([&] { return w.preview()->bodyMesh(index) != nullptr && w.viewport()->meshCount() > 0; }, 600000)) {
        std::fprintf(stderr, "the preview did not build %s\n", project.c_str());
        return -1;
    }
    w.selectBody(index);
    return index;
}

} // namespace viscera::bench
