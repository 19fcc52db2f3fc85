#pragma once
/// Recorded master trajectories: what the replay backend plays and viscera-console-sim sends.
///
/// File format (text, one sample per line, '#' starts a comment line):
///   # viscera-trajectory 1
///   t,arm,x,y,z,qw,qx,qy,qz,grip,buttons,pedals
///   0.000,0,0.0,0.0,0.05,1,0,0,0,0.2,0,4
/// t: s from the start (strictly increasing per arm); arm: 0 or 1; x, y, z: m in the device base
/// frame; qw..qz: orientation (normalised on load; its norm must be within 10% of 1); grip: jaw
/// opening in [0, π] rad; buttons: unsigned integer bit set; pedals: Pedal bits in [0, 31].
/// Between samples position and grip are interpolated linearly, orientation by slerp; buttons and
/// pedals hold the previous sample's value. Before the first sample the first holds, after the
/// last the last holds (or the trajectory loops).
#include "haptics/types.hpp"

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::haptics {

struct TrajectorySample {
    double t = 0; ///< s
    Pose pose;
    double grip = 0; ///< rad
    uint32_t buttons = 0;
    uint32_t pedals = 0;
};

class Trajectory {
public:
    /// Throws viscera::InputError "<origin>: line 7: field 'qw': not a number" (the line, the
    /// field and the rule) on any malformed line, and when no sample is present.
    static Trajectory parse(std::string_view text, const std::string& origin);
    static Trajectory load(const std::filesystem::path& path);
    std::string format() const;

    /// Appends a sample to arm `arm` (0..kMaxArms-1); t must exceed the arm's last t.
    /// Throws std::invalid_argument otherwise.
    void add(int arm, const TrajectorySample& s);
    int arms() const;        ///< 1 + highest arm index with samples (0 if empty)
    double duration() const; ///< s, the latest sample time over all arms
    const std::vector<TrajectorySample>& samples(int arm) const { return m_arms[arm]; }

    /// State at time t (s): pose, grip, buttons of each arm, pedals (OR over arms), twist from
    /// the bracketing samples. O(log n), allocation-free. With loop, t wraps over duration().
    void sampleInto(double t, bool loop, DeviceState& out) const;

private:
    std::array<std::vector<TrajectorySample>, kMaxArms> m_arms;
};

} // namespace viscera::haptics
