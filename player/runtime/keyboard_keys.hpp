#pragma once
/// Which Qt key drives which key of the keyboard master (haptics::KeyboardDevice): arrows move
/// x/y, Page Up/Down move z, Space holds the clutch, C the camera pedal, G closes the grip, E holds
/// the energy (cut) pedal, B presses the arm's button (the next instrument of the hand). One table for the
/// trainee window and the studio's rehearsal. Header only, for the Qt front ends (the runtime
/// itself does not link Qt).
#include "haptics/keyboard_device.hpp"

#include <QtCore/qnamespace.h>

#include <optional>

namespace viscera::player {

inline std::optional<haptics::KeyboardDevice::Key> keyboardKey(int qtKey) {
    using K = haptics::KeyboardDevice;
    switch (qtKey) {
    case Qt::Key_Left:
        return K::KeyLeft;
    case Qt::Key_Right:
        return K::KeyRight;
    case Qt::Key_Up:
        return K::KeyUp;
    case Qt::Key_Down:
        return K::KeyDown;
    case Qt::Key_PageUp:
        return K::KeyPageUp;
    case Qt::Key_PageDown:
        return K::KeyPageDown;
    case Qt::Key_Space:
        return K::KeyClutch;
    case Qt::Key_C: // held: the Cam pedal
        return K::KeyCamera;
    case Qt::Key_G:
        return K::KeyGrip;
    case Qt::Key_E:
        return K::KeyCut;
    case Qt::Key_B:
        return K::KeyButton;
    default:
        return std::nullopt;
    }
}

} // namespace viscera::player
