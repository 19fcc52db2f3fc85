#include "haptics/keyboard_device.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::haptics {

KeyboardDevice::KeyboardDevice(double speed, double metresPerPixel) : m_speed(speed), m_mpp(metresPerPixel) {
    m_caps.name = "keyboard";
    m_caps.arms = 1;
    m_caps.arm[0].hand = Hand::Either;
    m_caps.arm[0].dof = 3;
    m_caps.arm[0].grip = true; // the grip key
    m_caps.arm[0].maxForce = 0.0;
    m_caps.pedals = 0;
    m_caps.realtime = true;
}

void KeyboardDevice::setKey(Key key, bool down) {
    if (down)
        m_keys.fetch_or(key, std::memory_order_relaxed);
    else
        m_keys.fetch_and(~uint32_t(key), std::memory_order_relaxed);
}

void KeyboardDevice::addMouse(double dx, double dy, double wheel) {
    m_mouseX.fetch_add(std::llround(dx * 1000), std::memory_order_relaxed);
    m_mouseY.fetch_add(std::llround(dy * 1000), std::memory_order_relaxed);
    m_wheel.fetch_add(std::llround(wheel * 1000), std::memory_order_relaxed);
}

void KeyboardDevice::poll(int64_t now_ns, DeviceState& out) {
    const double dt = m_started ? std::clamp(1e-9 * double(now_ns - m_last_ns), 0.0, 0.1) : 0.0;
    m_started = true;
    m_last_ns = now_ns;
    const uint32_t k = m_keys.load(std::memory_order_relaxed);
    auto held = [k](uint32_t key) { return (k & key) ? 1.0 : 0.0; };
    const Vec3 dir(held(KeyRight) - held(KeyLeft), held(KeyUp) - held(KeyDown), held(KeyPageUp) - held(KeyPageDown));
    const Vec3 before = m_pos;
    m_pos += m_speed * dt * dir;
    const int64_t mx = m_mouseX.load(std::memory_order_relaxed), my = m_mouseY.load(std::memory_order_relaxed),
                  mw = m_wheel.load(std::memory_order_relaxed);
    m_pos += Vec3(1e-3 * m_mpp * double(mx - m_seenX), -1e-3 * m_mpp * double(my - m_seenY),
                  1e-3 * 0.005 * double(mw - m_seenWheel));
    m_seenX = mx, m_seenY = my, m_seenWheel = mw;
    const ArmCapabilities& a = m_caps.arm[0];
    m_pos = m_pos.cwiseMax(a.workspaceMin).cwiseMin(a.workspaceMax);
    m_vel = dt > 0 ? Vec3((m_pos - before) / dt) : Vec3::Zero();
    out.timestamp_ns = now_ns;
    out.sequence = ++m_seq;
    out.connected = true;
    out.pedals = ((k & KeyClutch) ? uint32_t(kPedalClutch) : 0u) | ((k & KeyCamera) ? uint32_t(kPedalCamera) : 0u) |
                 ((k & KeyCut) ? uint32_t(kPedalEnergyCut) : 0u);
    out.arms[0].jaw_measured_js = (k & KeyGrip) ? 0.0 : kOpenGrip;
    out.arms[0].buttons = (k & KeyButton) ? 1u : 0u;
    out.arms[0].measured_cp.position = m_pos;
    out.arms[0].measured_cp.orientation = Quat::Identity();
    out.arms[0].measured_cv.linear = m_vel;
    out.arms[0].measured_cv.angular.setZero();
    countPoll();
}

} // namespace viscera::haptics
