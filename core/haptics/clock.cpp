#include "haptics/clock.hpp"

#include <time.h>

namespace viscera::haptics {

int64_t monotonicNs() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

int64_t SteadyClock::now_ns() const { return monotonicNs(); }

} // namespace viscera::haptics
