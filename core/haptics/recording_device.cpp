#include "haptics/recording_device.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::haptics {

RecordingDevice::RecordingDevice(Device& inner, double seconds, double interval) : m_inner(inner) {
    // NaN, negative or absurd requests become sane ones: 1 ms .. 10 s per sample, up to a day.
    interval = std::isfinite(interval) ? std::clamp(interval, 1e-3, 10.0) : 0.01;
    seconds = std::isfinite(seconds) ? std::clamp(seconds, 0.0, 86400.0) : 0.0;
    m_interval_ns = static_cast<int64_t>(interval * 1e9);
    const int arms = std::clamp(inner.capabilities().arms, 1, kMaxArms);
    // One row per arm per interval, a quarter more for the changes between them.
    m_rows.resize(static_cast<size_t>(1.25 * arms * seconds / interval) + 16);
}

void RecordingDevice::poll(int64_t now_ns, DeviceState& out) {
    m_inner.poll(now_ns, out);
    if (m_full.load(std::memory_order_relaxed)) return;
    if (!m_started) {
        m_started = true;
        m_t0 = now_ns;
        m_last = now_ns - m_interval_ns; // the first poll is a sample
    }
    const int arms = std::clamp(m_inner.capabilities().arms, 1, kMaxArms);
    bool changed = out.pedals != m_pedals;
    for (int a = 0; a < arms; ++a)
        changed = changed || out.arms[a].buttons != m_buttons[a];
    if (!changed && now_ns - m_last < m_interval_ns) return;
    size_t n = m_count.load(std::memory_order_relaxed);
    if (n + arms > m_rows.size()) {
        m_full.store(true, std::memory_order_release);
        return;
    }
    const double t = static_cast<double>(now_ns - m_t0) * 1e-9;
    for (int a = 0; a < arms; ++a) {
        const ArmState& s = out.arms[a];
        Row& r = m_rows[n++];
        r.t = t;
        r.arm = a;
        r.sample.t = t;
        r.sample.pose = s.measured_cp;
        r.sample.grip = std::isfinite(s.jaw_measured_js) ? s.jaw_measured_js : 0.0;
        r.sample.buttons = s.buttons;
        r.sample.pedals = out.pedals & kPedalMask;
        m_buttons[a] = s.buttons;
    }
    m_pedals = out.pedals;
    m_last = now_ns;
    m_count.store(n, std::memory_order_release);
}

Trajectory RecordingDevice::trajectory() const {
    // Two polls on one instant (a servo that caught up): the later one holds what the device
    // said last, a press seen on it included.
    std::array<std::vector<TrajectorySample>, kMaxArms> arms;
    const size_t n = m_count.load(std::memory_order_acquire);
    for (size_t i = 0; i < n; ++i) {
        const Row& r = m_rows[i];
        if (!r.sample.pose.position.allFinite() || !r.sample.pose.orientation.coeffs().allFinite()) continue;
        std::vector<TrajectorySample>& a = arms[static_cast<size_t>(r.arm)];
        if (!a.empty() && !(r.t > a.back().t))
            a.back() = r.sample;
        else
            a.push_back(r.sample);
    }
    Trajectory t;
    for (int a = 0; a < kMaxArms; ++a)
        for (const TrajectorySample& s : arms[static_cast<size_t>(a)])
            t.add(a, s);
    return t;
}

double RecordingDevice::recordedSeconds() const {
    const size_t n = m_count.load(std::memory_order_acquire);
    return n ? m_rows[n - 1].t : 0.0;
}

} // namespace viscera::haptics
