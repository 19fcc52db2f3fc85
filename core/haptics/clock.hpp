#pragma once
/// Clocks for the servo loop and the devices: the monotonic wall clock, and a manual clock that
/// only moves when told to (replay and tests run on it, so a session is repeatable).
#include <atomic>
#include <cstdint>

namespace viscera::haptics {

class Clock {
public:
    virtual ~Clock() = default;
    /// Nanoseconds since an arbitrary epoch; never decreases. Lock-free, allocation-free.
    virtual int64_t now_ns() const = 0;
};

/// CLOCK_MONOTONIC.
class SteadyClock final : public Clock {
public:
    int64_t now_ns() const override;
};

/// A deterministic clock: now_ns() returns what set() or advance() last made it.
class ManualClock final : public Clock {
public:
    explicit ManualClock(int64_t start_ns = 0) : m_now(start_ns) {}
    int64_t now_ns() const override { return m_now.load(std::memory_order_acquire); }
    void set(int64_t t_ns) { m_now.store(t_ns, std::memory_order_release); }
    void advance(int64_t dt_ns) { m_now.fetch_add(dt_ns, std::memory_order_acq_rel); }

private:
    std::atomic<int64_t> m_now;
};

/// The monotonic clock as a free function (for code that has no Clock object at hand).
int64_t monotonicNs();
/// Sleeps until CLOCK_MONOTONIC reaches t_ns (absolute; resumes after signals).
void sleepUntilNs(int64_t t_ns);

} // namespace viscera::haptics
