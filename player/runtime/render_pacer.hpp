#pragma once
/// When the trainee window renders its 3D view, so that the view never takes the time the
/// physics needs. A render of R ms (tens of ms on a software rasterizer without a GPU, ~1 ms
/// with one) runs on the same cores as the physics; it is due when
///   - the physics has kept up: its frame started no later than the least lag seen since the
///     warm-up plus one frame (a slow start's offset does not count), and
///   - at least R · max(kMinGapFactor, 2 / spare) ms passed since the last render, spare = 1 −
///     physics step / frame (the share of each frame the physics leaves idle): the renders take at
///     most half of that spare time, a quarter of all time at most;
/// and at least every kMaxGapMs whatever the physics does (the view never freezes), and once
/// more when the session finished. Pure logic: the window's timer asks it at every tick.
#include "runtime/haptic_rig.hpp"

namespace viscera::player {

class RenderPacer {
public:
    static constexpr double kMinGapFactor = 4.0;
    static constexpr double kMaxGapMs = 1000.0;

    /// The shortest time from the start of one render to the next, ms, for a render of renderMs
    /// with the physics at physicsMs per frameMs frame (<= 0: not known yet).
    static double minGapMs(double renderMs, double physicsMs, double frameMs);

    /// Whether to render now: s is the latest LiveState, sinceMs the time since the last render
    /// started (< 0: none yet), renderMs that render's duration. Call once per timer tick (it
    /// tracks the least lag).
    bool due(const LiveState& s, bool finished, double sinceMs, double renderMs);

private:
    double m_leastLagMs = -1;
};

} // namespace viscera::player
