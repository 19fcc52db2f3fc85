#include "plots/offscreen_gui.hpp"

#include <QGuiApplication>
#include <QString>

#include <clocale>
#include <cstdio>
#include <memory>

namespace viscera::player {

void ensureOffscreenGui() {
    if (QGuiApplication::instance()) return;
    // Nothing is written under the runtime folder; Qt's note that it is unset is noise here.
    static const QtMessageHandler previous =
        qInstallMessageHandler([](QtMsgType type, const QMessageLogContext& ctx, const QString& msg) {
            if (msg.startsWith("QStandardPaths: XDG_RUNTIME_DIR not set")) return;
            if (previous)
                previous(type, ctx, msg);
            else
                std::fprintf(stderr, "%s\n", msg.toLocal8Bit().constData());
        });
    static int argc = 3;
    static char arg0[] = "viscera", arg1[] = "-platform", arg2[] = "offscreen";
    static char* argv[] = {arg0, arg1, arg2, nullptr};
    static std::unique_ptr<QGuiApplication> app = std::make_unique<QGuiApplication>(argc, argv);
    std::setlocale(LC_NUMERIC, "C"); // Qt took the user's locale: figures keep their decimal point
}

} // namespace viscera::player
