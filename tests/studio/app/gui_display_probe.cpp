// gui_display_available: fails (exit 1, one line) when the GUI test step has no display or no
// OpenGL 4.1 core context there, so that skipped or silently passing GUI tests cannot hide a
// machine without Xvfb or Mesa. Prints the platform and the GL renderer when it can.
#include "app/studio_app.hpp"

#include <QApplication>
#include <QOffscreenSurface>
#include <QOpenGLContext>
#include <QOpenGLFunctions>

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
    if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY")) {
        std::fputs("gui_display_probe: no display (DISPLAY is not set): run the GUI tests under Xvfb (xvfb-run)\n",
                   stderr);
        return 1;
    }
    viscera::studio::setStudioSurfaceFormat();
    QApplication app(argc, argv);
    if (QGuiApplication::platformName() == "offscreen" || QGuiApplication::platformName() == "minimal") {
        std::fprintf(stderr, "gui_display_probe: platform '%s' is not a display\n",
                     QGuiApplication::platformName().toUtf8().constData());
        return 1;
    }
    QOffscreenSurface surface;
    surface.create();
    QOpenGLContext ctx;
    if (!ctx.create() || !ctx.makeCurrent(&surface)) {
        std::fputs("gui_display_probe: no OpenGL context on the display\n", stderr);
        return 1;
    }
    const auto f = ctx.format();
    const char* renderer = reinterpret_cast<const char*>(ctx.functions()->glGetString(GL_RENDERER));
    std::printf("display %s, platform %s, OpenGL %d.%d %s, %s\n", std::getenv("DISPLAY"),
                QGuiApplication::platformName().toUtf8().constData(), f.majorVersion(), f.minorVersion(),
                f.profile() == QSurfaceFormat::CoreProfile ? "core" : "compatibility", renderer ? renderer : "?");
    if (f.majorVersion() * 10 + f.minorVersion() < 41) {
        std::fputs("gui_display_probe: OpenGL 4.1 core is needed by the renderer\n", stderr);
        return 1;
    }
    return 0;
}
