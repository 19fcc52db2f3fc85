#include "haptics/scripted_device.hpp"

#include "sim/util/error.hpp"

#include <cmath>

namespace viscera::haptics {
namespace {

/// Press profile: 0 → -depth over 2 s, hold 1 s, back over 2 s (smoothstep ramps). Returns the
/// height and whether the arm is rising.
double pressHeight(double t, double depth, bool* rising) {
    const double period = 5.0;
    double u = std::fmod(t, period);
    auto smooth = [](double s) { return s * s * (3 - 2 * s); };
    if (rising) *rising = u >= 3.0;
    if (u < 2.0) return -depth * smooth(u / 2.0);
    if (u < 3.0) return -depth;
    return -depth * (1.0 - smooth((u - 3.0) / 2.0));
}

} // namespace

const std::vector<std::string>& ScriptedDevice::scripts() {
    static const std::vector<std::string> s = {"idle", "press", "circle", "bimanual", "clutch", "roll"};
    return s;
}

ScriptedDevice::ScriptedDevice(const std::string& script, double maxForce) {
    if (script == "idle")
        m_script = Script::Idle;
    else if (script == "press")
        m_script = Script::Press;
    else if (script == "circle")
        m_script = Script::Circle;
    else if (script == "bimanual")
        m_script = Script::Bimanual;
    else if (script == "clutch")
        m_script = Script::Clutch;
    else if (script == "roll")
        m_script = Script::Roll;
    else {
        std::string known;
        for (const auto& s : scripts())
            known += (known.empty() ? "" : ", ") + s;
        throw InputError("scripted:" + script + ": unknown script (known: " + known + ")");
    }
    m_caps.name = "scripted:" + script;
    m_caps.arms = (m_script == Script::Bimanual || m_script == Script::Idle) ? 2 : 1;
    m_caps.arm[0].hand = m_caps.arms == 2 ? Hand::Left : Hand::Either;
    m_caps.arm[1].hand = Hand::Right;
    for (auto& a : m_caps.arm)
        a.maxForce = maxForce;
    m_caps.pedals = 5;
}

void ScriptedDevice::poll(int64_t now_ns, DeviceState& out) {
    if (!m_started) {
        m_started = true;
        m_t0 = now_ns;
    }
    const double t = 1e-9 * double(now_ns - m_t0), h = 1e-3;
    out.timestamp_ns = now_ns;
    out.sequence = ++m_seq;
    out.connected = true;
    out.pedals = kPedalDeadman;
    auto position = [&](int arm, double s, bool* rising) -> Vec3 {
        switch (m_script) {
        case Script::Idle:
            return Vec3::Zero();
        case Script::Press:
        case Script::Clutch:
            return arm == 0 ? Vec3(0, 0, pressHeight(s, 0.09, rising)) : Vec3::Zero();
        case Script::Circle: {
            const double w = 2 * M_PI / 4.0;
            return arm == 0 ? Vec3(0.04 * std::cos(w * s), 0.04 * std::sin(w * s), -0.07) : Vec3::Zero();
        }
        case Script::Bimanual:
            return Vec3(0, 0, pressHeight(std::max(0.0, s - (arm == 1 ? 2.5 : 0.0)), 0.09, rising));
        case Script::Roll:
            return Vec3::Zero();
        }
        return Vec3::Zero();
    };
    // Roll: arm 0 turns its wrist about its own z axis, 0 → 150° over 3 s, holds 1 s, back over 3 s.
    auto roll = [&](double s) {
        if (m_script != Script::Roll) return 0.0;
        const double u = std::fmod(s, 8.0), full = 150.0 * M_PI / 180.0;
        auto smooth = [](double x) { return x * x * (3 - 2 * x); };
        if (u < 3.0) return full * smooth(u / 3.0);
        if (u < 4.0) return full;
        if (u < 7.0) return full * (1.0 - smooth((u - 4.0) / 3.0));
        return 0.0;
    };
    for (int a = 0; a < kMaxArms; ++a) {
        bool rising = false;
        ArmState& st = out.arms[a];
        st.measured_cp.position = position(a, t, &rising);
        st.measured_cp.orientation = a == 0 ? Quat(Eigen::AngleAxisd(roll(t), Vec3::UnitZ())) : Quat::Identity();
        st.measured_cv.linear =
            (position(a, t + h, nullptr) - position(a, std::max(0.0, t - h), nullptr)) / (t >= h ? 2 * h : h);
        st.measured_cv.angular =
            Vec3(0, 0, a == 0 ? (roll(t + h) - roll(std::max(0.0, t - h))) / (t >= h ? 2 * h : h) : 0.0);
        st.jaw_measured_js = 0.3;
        st.buttons = 0;
        if (a == 0 && m_script == Script::Clutch && rising) out.pedals |= kPedalClutch;
    }
    countPoll();
}

} // namespace viscera::haptics
