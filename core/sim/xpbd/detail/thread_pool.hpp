#pragma once
/// Persistent worker threads for the coloured constraint sweeps (private to sim/xpbd).
///
/// run(n, job) executes job(0), …, job(n−1) concurrently, job(0) on the calling thread, and
/// returns when all have finished. Waiting spins briefly, yields, and then sleeps on a futex
/// (std::atomic::wait), so idle workers cost nothing. One job at a time; not reentrant.
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace viscera::sim::detail {

class WorkerPool {
public:
    explicit WorkerPool(int threads); ///< threads ≥ 1 (threads − 1 workers are started)
    ~WorkerPool();
    WorkerPool(const WorkerPool&) = delete;
    WorkerPool& operator=(const WorkerPool&) = delete;

    int size() const { return static_cast<int>(m_workers.size()) + 1; }
    /// Runs job(tid) for tid in [0, n), n ≤ size(); no allocation.
    template <class Job> void run(int n, const Job& job) {
        run(
            n, [](const void* j, int tid) { (*static_cast<const Job*>(j))(tid); }, &job);
    }

private:
    using Trampoline = void (*)(const void*, int);
    void run(int n, Trampoline call, const void* job);
    void workerLoop(int tid);

    std::vector<std::thread> m_workers;
    Trampoline m_call = nullptr;
    const void* m_job = nullptr;
    int m_jobThreads = 1;
    bool m_stop = false;
    alignas(64) std::atomic<uint32_t> m_generation{0};
    alignas(64) std::atomic<int> m_pending{0};
};

} // namespace viscera::sim::detail
