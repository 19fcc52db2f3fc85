#pragma once
/// Entry of the desktop studio (viscera-studio with no subcommand, or `open <project-dir>`).
/// Only this creates a Qt application object; the headless subcommands never call it.
#include <QString>

namespace viscera::studio {

/// Requests an OpenGL 4.1 core context (the renderer's minimum) for every GL surface of the studio
/// (the viewport's render-thread window and its QOpenGLWidget host); call
/// before the QApplication is created.
void setStudioSurfaceFormat();

/// Runs the studio's main window until it is closed; `folder` (may be empty) is opened first.
/// Returns the application's exit code; 1 with one line on stderr when no display can be used.
int runStudio(int argc, char** argv, const QString& folder);

} // namespace viscera::studio
