#include "app/studio_app.hpp"

#include "app/main_window.hpp"

#include <QApplication>
#include <QGuiApplication>
#include <QSurfaceFormat>

#include <cstdio>
#include <cstdlib>

namespace viscera::studio {

void setStudioSurfaceFormat() {
    QSurfaceFormat f;
    f.setRenderableType(QSurfaceFormat::OpenGL);
    f.setVersion(4, 1);
    f.setProfile(QSurfaceFormat::CoreProfile);
    f.setDepthBufferSize(24);
    QSurfaceFormat::setDefaultFormat(f);
}

int runStudio(int argc, char** argv, const QString& folder) {
    if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY") && !std::getenv("QT_QPA_PLATFORM")) {
        std::fputs("viscera-studio: no display (DISPLAY is not set); the headless commands are export and import "
                   "(see --help)\n",
                   stderr);
        return 1;
    }
    setStudioSurfaceFormat();
    QApplication app(argc, argv);
    QCoreApplication::setOrganizationName("Viscera");
    QCoreApplication::setApplicationName("Studio");
    QCoreApplication::setApplicationVersion(VISCERA_VERSION);
    MainWindow window;
    window.resize(1500, 950);
    window.show();
    if (!folder.isEmpty() && !window.openProject(folder)) {
        // the message is in the log and status bar; the window stays open for another project
    }
    return app.exec();
}

} // namespace viscera::studio
