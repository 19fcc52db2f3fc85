#pragma once
/// Keyboard/mouse backend for the trainee window: the window (GUI thread) reports keys and mouse
/// motion through lock-free setters; poll() (servo thread) integrates them into arm 0's pose.
/// Keys move the master at `speed` m/s: Left/Right = ∓x/±x, Up/Down = ±y, PageUp/PageDown = ±z;
/// the clutch key holds the clutch pedal. Mouse drags move x/y by metresPerPixel per pixel and
/// the wheel moves z. Positions stay inside the workspace. The grip key closes the jaws while held
/// (grip 0 rad, else open at kOpenGrip), the cut key holds the energy (cut) pedal, the button key
/// presses the arm's first button (which hands the arm to the next instrument of its hand). No
/// force can be rendered: the device has no motors, so commands are only recorded.
#include "haptics/device.hpp"

#include <atomic>

namespace viscera::haptics {

class KeyboardDevice final : public LocalDevice {
public:
    enum Key : uint32_t {
        KeyLeft = 1,
        KeyRight = 2,
        KeyUp = 4,
        KeyDown = 8,
        KeyPageUp = 16,
        KeyPageDown = 32,
        KeyClutch = 64,
        KeyCamera = 128, ///< the Cam pedal: the keys steer the laparoscope
        KeyGrip = 256,   ///< held: the jaws closed
        KeyCut = 512,    ///< held: the energy (cut) pedal
        KeyButton = 1024 ///< held: the arm's first button
    };
    static constexpr uint32_t kAllKeys = 2047;
    static constexpr double kOpenGrip = 1.0; ///< rad, the grip while the grip key is up
    explicit KeyboardDevice(double speed = 0.05, double metresPerPixel = 2e-4);
    const DeviceCapabilities& capabilities() const override { return m_caps; }
    void poll(int64_t now_ns, DeviceState& out) override;
    const char* backend() const override { return "keyboard"; }

    // GUI thread:
    void setKey(Key key, bool down);
    void addMouse(double dxPixels, double dyPixels, double wheelSteps);

private:
    DeviceCapabilities m_caps;
    double m_speed, m_mpp;
    std::atomic<uint32_t> m_keys{0};
    std::atomic<int64_t> m_mouseX{0}, m_mouseY{0}, m_wheel{0}; ///< accumulated, in 1e-3 pixel / step
    int64_t m_seenX = 0, m_seenY = 0, m_seenWheel = 0;
    Vec3 m_pos = Vec3::Zero();
    Vec3 m_vel = Vec3::Zero();
    int64_t m_last_ns = 0;
    bool m_started = false;
    uint64_t m_seq = 0;
};

} // namespace viscera::haptics
