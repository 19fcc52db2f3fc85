#pragma once
/// Persistent worker threads for the coloured constraint sweeps (private to sim/xpbd).
///
/// run(n, job) executes job(0..n−1) concurrently, job(0) on the calling thread, and returns when
/// all have finished. Waiting spins briefly and then sleeps on a futex (std::atomic::wait), so
/// idle workers cost nothing. One job at a time; not reentrant.
#include <atomic>
#include <cstdint>
#include <functional>
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
    void run(int n, const std::function<void(int)>& job);

private:
    void workerLoop(int tid);

    std::vector<std::thread> m_workers;
    const std::function<void(int)>* m_job = nullptr;
    int m_jobThreads = 1;
    bool m_stop = false;
    alignas(64) std::atomic<uint32_t> m_generation{0};
    alignas(64) std::atomic<int> m_pending{0};
};

} // namespace viscera::sim::detail
