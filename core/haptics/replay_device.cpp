#include "haptics/replay_device.hpp"

namespace viscera::haptics {

ReplayDevice::ReplayDevice(Trajectory trajectory, const ReplayOptions& options)
    : m_traj(std::move(trajectory)), m_opt(options) {
    m_caps.name = options.name;
    m_caps.arms = std::max(1, m_traj.arms());
    m_caps.arm[0].hand = m_caps.arms == 2 ? Hand::Left : Hand::Either;
    m_caps.arm[1].hand = Hand::Right;
    for (auto& a : m_caps.arm)
        a.maxForce = options.maxForce;
    m_caps.pedals = 5;
    m_caps.realtime = false;
}

void ReplayDevice::poll(int64_t now_ns, DeviceState& out) {
    if (!m_started) {
        m_started = true;
        m_t0 = now_ns;
    }
    m_traj.sampleInto(1e-9 * double(now_ns - m_t0), m_opt.loop, out);
    out.timestamp_ns = now_ns;
    out.sequence = ++m_seq;
    out.connected = true;
    countPoll();
}

} // namespace viscera::haptics
