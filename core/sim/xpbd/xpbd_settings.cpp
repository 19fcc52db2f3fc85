#include "sim/xpbd/xpbd_settings.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include <sched.h>

namespace viscera::sim {

int defaultXpbdThreads() {
    // The CPUs this thread may run on (the player keeps a real-time servo's CPU out of the set).
    cpu_set_t set;
    CPU_ZERO(&set);
    unsigned n = sched_getaffinity(0, sizeof(set), &set) == 0 ? static_cast<unsigned>(CPU_COUNT(&set)) : 0u;
    if (n == 0) n = std::thread::hardware_concurrency();
    return static_cast<int>(std::clamp(n == 0 ? 2u : n, 1u, 8u));
}

std::string validate(const XpbdSettings& s) {
    using L = XpbdLimits;
    if (!std::isfinite(s.dt) || s.dt <= 0 || s.dt > L::maxDt) return "dt must be in (0, 0.1] s";
    if (s.substeps < 1 || s.substeps > L::maxSubsteps) return "substeps must be in [1, 1000]";
    if (s.iterations < 1 || s.iterations > L::maxIterations) return "iterations must be in [1, 1000]";
    if (!std::isfinite(s.damping) || s.damping < 0 || s.damping > L::maxDamping)
        return "damping must be in [0, 1000] 1/s";
    if (!s.gravity.allFinite() || s.gravity.norm() > L::maxGravity)
        return "gravity must be finite and at most 1000 m/s^2";
    if (!std::isfinite(s.maxSpeed) || s.maxSpeed <= 0) return "max_speed must be positive";
    if (s.threads < 1 || s.threads > L::maxThreads) return "threads must be in [1, 64]";
    if (!(s.inertiaScaling >= 1 && s.inertiaScaling <= L::maxInertiaScaling))
        return "inertia_scaling must be in [1, 100]";
    return {};
}

} // namespace viscera::sim
