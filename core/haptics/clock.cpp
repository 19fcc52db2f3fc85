#include "haptics/clock.hpp"

#include <cerrno>
#include <time.h>

namespace viscera::haptics {

int64_t monotonicNs() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleepUntilNs(int64_t t_ns) {
    timespec ts{};
    ts.tv_sec = t_ns / 1'000'000'000;
    ts.tv_nsec = t_ns % 1'000'000'000;
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
}

int64_t SteadyClock::now_ns() const {
    return monotonicNs();
}

} // namespace viscera::haptics
