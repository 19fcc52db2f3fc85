#pragma once
/// Scripted backend: named, procedural master motions evaluated on the servo clock (allocation-
/// free, repeatable on a ManualClock). Positions are relative to the workspace centre, in the
/// device base frame (z up). The deadman pedal is held throughout.
///   idle       both arms hold still at the centre
///   press      arm 0 descends 9 cm over 2 s, holds 1 s, rises over 2 s; period 5 s
///   circle     arm 0 circles (radius 4 cm, period 4 s) 7 cm below the centre
///   bimanual   both arms press alternately (arm 1 starts half a period, 2.5 s, after arm 0)
///   clutch     like press, with the clutch pedal held during the rise
///   roll       arm 0 stays at the centre and turns its wrist about its own z axis, 0 → 150° over
///              3 s, holds 1 s, back over 3 s; period 8 s (drives a needle along its curve)
#include "haptics/device.hpp"

#include <atomic>
#include <string>
#include <vector>

namespace viscera::haptics {

class ScriptedDevice final : public LocalDevice {
public:
    /// Throws viscera::InputError "scripted:<name>: unknown script (known: idle, press, ...)".
    explicit ScriptedDevice(const std::string& script, double maxForce = 15.0);
    static const std::vector<std::string>& scripts();
    const DeviceCapabilities& capabilities() const override { return m_caps; }
    void poll(int64_t now_ns, DeviceState& out) override;
    const char* backend() const override { return "scripted"; }

private:
    enum class Script { Idle, Press, Circle, Bimanual, Clutch, Roll };
    Script m_script;
    DeviceCapabilities m_caps;
    bool m_started = false;
    int64_t m_t0 = 0;
    uint64_t m_seq = 0;
};

} // namespace viscera::haptics
