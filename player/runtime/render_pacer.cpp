#include "runtime/render_pacer.hpp"

#include "runtime/realtime_watch.hpp"

#include <algorithm>

namespace viscera::player {

double RenderPacer::minGapMs(double renderMs, double physicsMs, double frameMs) {
    const double r = std::max(0.0, renderMs);
    if (!(physicsMs > 0) || !(frameMs > 0)) return kMinGapFactor * r;
    const double spare = 1.0 - physicsMs / frameMs;
    if (!(spare > 0)) return kMaxGapMs; // no time to spare: only the once-a-second view
    return std::min(kMaxGapMs, r * std::max(kMinGapFactor, 2.0 / spare));
}

bool RenderPacer::due(const LiveState& s, bool finished, double sinceMs, double renderMs) {
    const double frameMs = s.frame > 0 ? 1e3 * s.time_s / s.frame : 0.0;
    if (s.frame > static_cast<int>(RealTimeWatch::kWarmupFrames))
        m_leastLagMs = m_leastLagMs < 0 ? s.lagMs : std::min(m_leastLagMs, s.lagMs);
    if (finished || sinceMs < 0 || sinceMs >= kMaxGapMs) return true;
    const bool keptUp = m_leastLagMs < 0 || s.lagMs <= m_leastLagMs + frameMs;
    return keptUp && sinceMs >= minGapMs(renderMs, s.physicsMs, frameMs);
}

} // namespace viscera::player
