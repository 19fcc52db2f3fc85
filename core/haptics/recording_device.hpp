#pragma once
/// A device that records what another did, as a Trajectory (trajectory.hpp), while passing
/// everything through: the studio's rehearsal keeps a session as the case's reference replay.
///
/// poll() (servo thread) stores a sample of every arm in a buffer reserved up front (no
/// allocation, no lock): every `interval` of servo time and at every change of an arm's buttons or
/// of the pedals, so a button press or a pedal lands on the tick it happened. Time zero is the
/// first poll. When the buffer is full, recording stops (full() says so); the device goes on.
/// The buffer is reserved in the constructor (about 110 bytes per row, 1.25 rows per arm and
/// interval: 15 minutes of two arms at 10 ms take 25 MB).
/// Between its samples the replay interpolates position and grip linearly and orientation by
/// slerp: at the default 10 ms the recorded path differs from the live one by what the hands did
/// within 10 ms.
#include "haptics/device.hpp"
#include "haptics/trajectory.hpp"

#include <atomic>
#include <vector>

namespace viscera::haptics {

class RecordingDevice final : public Device {
public:
    /// Records `inner` (not owned; outlives this) for up to `seconds` of servo time, one sample
    /// per arm every `interval` s (and at changes).
    explicit RecordingDevice(Device& inner, double seconds = 900.0, double interval = 0.01);
    const DeviceCapabilities& capabilities() const override { return m_inner.capabilities(); }
    void poll(int64_t now_ns, DeviceState& out) override;
    void send(const DeviceCommand& command) override { m_inner.send(command); }
    LinkStats linkStats() const override { return m_inner.linkStats(); }
    const char* backend() const override { return m_inner.backend(); }

    // After the servo thread stopped (or, for the counts, at any time):
    /// What was recorded, arm by arm (empty when nothing was polled).
    Trajectory trajectory() const;
    size_t samples() const { return m_count.load(std::memory_order_acquire); }
    bool full() const { return m_full.load(std::memory_order_acquire); }
    double recordedSeconds() const; ///< servo time of the last sample, s

private:
    struct Row {
        double t;
        int arm;
        TrajectorySample sample;
    };
    Device& m_inner;
    int64_t m_interval_ns = 10'000'000;
    std::vector<Row> m_rows; ///< reserved; rows [0, m_count) are written
    std::atomic<size_t> m_count{0};
    std::atomic<bool> m_full{false};
    bool m_started = false;
    int64_t m_t0 = 0, m_last = 0;
    std::array<uint32_t, kMaxArms> m_buttons{};
    uint32_t m_pedals = 0;
};

} // namespace viscera::haptics
