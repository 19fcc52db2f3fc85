// Built when Qt6 Gui is not available: the player is headless only.
#include "window/window_mode.hpp"

namespace viscera::player {

std::string windowModeUnavailable() {
    return "window mode needs Qt6 Gui, which this build does not include; use --headless";
}

SessionResult runWindow(LoadedCase& loaded, RunOptions options, const WindowShots&) {
    return runSession(loaded, options);
}

} // namespace viscera::player
