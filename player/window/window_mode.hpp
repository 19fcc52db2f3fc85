#pragma once
/// The trainee window: case title, instructions, the task's numbered steps, timer,
/// device/pedal/clutch state, force bars and a side view of the tissue and tools (QtGui raster
/// window, no Qt Widgets, no editing UI).
/// Built only when Qt6 Gui is found (window_mode_qt.cpp); otherwise window_mode_none.cpp
/// refuses window mode with a message.
#include "runtime/session.hpp"

#include <string>

namespace viscera::player {

/// Empty when window mode can run here; otherwise the one-line reason (no Qt in this build, no
/// display and no QT_QPA_PLATFORM).
std::string windowModeUnavailable();

/// PNG files the window writes (atomically) when not empty: the view at the session's last frame,
/// and the end-of-session screen (the verdict).
struct WindowShots {
    std::string view, endScreen;
};

/// Runs the session on a physics thread while the window shows it (the GUI thread owns the
/// window). When the session ends the window shows its verdict (window/verdict_screen.hpp).
/// options.frames = 0 runs until the trainee ends it (closing the window or Esc), then shows the
/// verdict until the window is closed again (Enter, Esc); otherwise the window closes when the
/// frames are done, after writing `shots`. Keys and the mouse drive a KeyboardDevice when
/// options.device is one.
SessionResult runWindow(LoadedCase& loaded, RunOptions options, const WindowShots& shots);

} // namespace viscera::player
