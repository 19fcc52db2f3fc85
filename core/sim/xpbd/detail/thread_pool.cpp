#include "sim/xpbd/detail/thread_pool.hpp"

#include "sim/util/cpu_relax.hpp"

#include <cassert>

namespace viscera::sim::detail {
namespace {

/// Spins up to `spins` rounds for `a` to differ from `old`, yields the core a few times (on a
/// busy machine the thread we wait for may be queued behind us), then sleeps until it differs.
template <class T> void waitWhileEquals(const std::atomic<T>& a, T old, int spins) {
    for (int i = 0; i < spins; ++i) {
        if (a.load(std::memory_order_acquire) != old) return;
        cpuRelax();
    }
    for (int i = 0; i < 64; ++i) {
        if (a.load(std::memory_order_acquire) != old) return;
        std::this_thread::yield();
    }
    while (a.load(std::memory_order_acquire) == old)
        a.wait(old, std::memory_order_acquire);
}

constexpr int kDoneSpins = 256;
constexpr int kIdleSpins = 2000;

} // namespace

WorkerPool::WorkerPool(int threads) {
    for (int t = 1; t < threads; ++t)
        m_workers.emplace_back([this, t] { workerLoop(t); });
}

WorkerPool::~WorkerPool() {
    m_stop = true;
    m_generation.fetch_add(1, std::memory_order_release);
    m_generation.notify_all();
    for (std::thread& w : m_workers)
        w.join();
}

void WorkerPool::workerLoop(int tid) {
    uint32_t seen = 0;
    for (;;) {
        waitWhileEquals(m_generation, seen, kIdleSpins);
        seen = m_generation.load(std::memory_order_acquire);
        if (m_stop) return;
        if (tid < m_jobThreads) m_call(m_job, tid);
        if (m_pending.fetch_sub(1, std::memory_order_acq_rel) == 1) m_pending.notify_one();
    }
}

void WorkerPool::run(int n, Trampoline call, const void* job) {
    assert(n >= 1 && n <= size());
    if (n == 1 || m_workers.empty()) {
        m_jobThreads = 1;
        call(job, 0);
        return;
    }
    m_call = call;
    m_job = job;
    m_jobThreads = n;
    m_pending.store(static_cast<int>(m_workers.size()), std::memory_order_relaxed);
    m_generation.fetch_add(1, std::memory_order_release);
    m_generation.notify_all();
    call(job, 0);
    for (;;) {
        const int p = m_pending.load(std::memory_order_acquire);
        if (p == 0) break;
        waitWhileEquals(m_pending, p, kDoneSpins);
    }
    m_job = nullptr;
}

} // namespace viscera::sim::detail
