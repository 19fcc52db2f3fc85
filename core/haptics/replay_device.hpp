#pragma once
/// Replay backend: plays a recorded Trajectory on the servo clock. Time zero is the first poll;
/// with a ManualClock the session is repeatable bit for bit. Forces sent are kept (the last
/// command) so tests can inspect them; the replay never disconnects.
#include "haptics/device.hpp"
#include "haptics/trajectory.hpp"

#include <atomic>

namespace viscera::haptics {

struct ReplayOptions {
    bool loop = false;      ///< wrap around at the end (otherwise the last sample holds)
    double maxForce = 15.0; ///< N, reported capability
    std::string name = "replay";
};

class ReplayDevice final : public LocalDevice {
public:
    ReplayDevice(Trajectory trajectory, const ReplayOptions& options = {});
    const DeviceCapabilities& capabilities() const override { return m_caps; }
    void poll(int64_t now_ns, DeviceState& out) override;
    const char* backend() const override { return "replay"; }
    const Trajectory& trajectory() const { return m_traj; }

private:
    Trajectory m_traj;
    ReplayOptions m_opt;
    DeviceCapabilities m_caps;
    bool m_started = false;
    int64_t m_t0 = 0;
    uint64_t m_seq = 0;
};

} // namespace viscera::haptics
