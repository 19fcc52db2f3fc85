#pragma once
/// Recorded instrument tracks: where a scripted instrument (grasper, energy hook, clip applier) is
/// at each moment of a case, as a small text file carried in the case package.
///
///   # viscera instrument track 1
///   # t[s]  x y z[m]  dx dy dz (shaft direction, towards the tip)  jaw[0 closed..1 open]  act[0|1]
///   0.00    0.0 0.0 0.03   0 0 -1   1.0   0
///   1.50    0.0 0.0 0.002  0 0 -1   0.0   1
///
/// Lines: a header line "# viscera instrument track 1" first, then comments (#) or keys of 9
/// numbers. Times strictly increase; positions and directions are finite; directions non-zero;
/// jaw in [0, 1]; act 0 or 1 (energy on, clip fired, ...). Between keys the pose is interpolated
/// linearly (direction: normalised linear blend), jaw linearly; act holds the earlier key's value.
/// Before the first key the first pose is held, after the last key the last one.
#include <Eigen/Core>

#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

using Vec3 = Eigen::Vector3d;

struct InstrumentKey {
    double t = 0;                    ///< s
    Vec3 position = Vec3::Zero();    ///< m, scene: tip
    Vec3 direction = -Vec3::UnitZ(); ///< unit, shaft towards the tip
    double jaw = 1;                  ///< 0 closed … 1 open
    bool act = false;                ///< energy on / clip fired
    double roll = 0;                 ///< rad about the shaft (a device's; tracks carry none)
};

class InstrumentTrack {
public:
    InstrumentTrack() = default;
    /// Throws viscera::InputError "<origin>:<line>: <field>: <rule>".
    static InstrumentTrack parse(std::string_view text, const std::string& origin);
    std::string format() const;
    /// Keys must follow the rules above (throws std::invalid_argument otherwise).
    explicit InstrumentTrack(std::vector<InstrumentKey> keys);

    InstrumentKey sample(double t) const;
    const std::vector<InstrumentKey>& keys() const { return m_keys; }
    double duration() const { return m_keys.empty() ? 0.0 : m_keys.back().t; }

private:
    std::vector<InstrumentKey> m_keys;
};

} // namespace viscera::sim
