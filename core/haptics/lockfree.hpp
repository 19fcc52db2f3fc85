#pragma once
/// Lock-free hand-over between the servo thread and the physics/GUI threads.
///
/// SeqLock<T>: one writer, any number of readers. write() is wait-free (the servo or physics
/// thread never waits for a reader); read() retries only while a write is in progress (a few
/// hundred nanoseconds at most). The payload is stored as relaxed atomic words, so there is no
/// data race in the C++ memory model. T must be bitwise copyable and trivially destructible
/// (plain structs of numbers, fixed-size Eigen vectors and quaternions, std::array of those).
///
/// SpscRing<T>: a bounded single-producer single-consumer queue; push() fails (and counts a
/// drop) when full instead of blocking or allocating.
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

namespace viscera::haptics {

template <class T> class SeqLock {
    static_assert(std::is_trivially_destructible_v<T>, "SeqLock<T> needs a bitwise-copyable, trivially destructible T");
    static constexpr size_t kWords = (sizeof(T) + 7) / 8;

public:
    SeqLock() {
        write(T{});
        m_writes.store(0, std::memory_order_relaxed);
    }
    explicit SeqLock(const T& v) { write(v); }

    void write(const T& v) noexcept {
        uint64_t buf[kWords] = {};
        std::memcpy(static_cast<void*>(buf), static_cast<const void*>(&v), sizeof(T));
        const uint64_t s = m_seq.load(std::memory_order_relaxed);
        m_seq.store(s + 1, std::memory_order_relaxed);
        std::atomic_thread_fence(std::memory_order_release);
        for (size_t i = 0; i < kWords; ++i)
            m_data[i].store(buf[i], std::memory_order_relaxed);
        m_seq.store(s + 2, std::memory_order_release);
        m_writes.fetch_add(1, std::memory_order_relaxed);
    }

    T read() const noexcept {
        uint64_t buf[kWords];
        while (true) {
            const uint64_t s0 = m_seq.load(std::memory_order_acquire);
            if (s0 & 1) continue;
            for (size_t i = 0; i < kWords; ++i)
                buf[i] = m_data[i].load(std::memory_order_relaxed);
            std::atomic_thread_fence(std::memory_order_acquire);
            if (m_seq.load(std::memory_order_relaxed) == s0) break;
        }
        T v;
        std::memcpy(static_cast<void*>(&v), static_cast<const void*>(buf), sizeof(T));
        return v;
    }

    uint64_t writes() const noexcept { return m_writes.load(std::memory_order_relaxed); }

private:
    std::atomic<uint64_t> m_seq{0};
    std::atomic<uint64_t> m_data[kWords] = {};
    std::atomic<uint64_t> m_writes{0};
};

template <class T> class SpscRing {
public:
    /// capacity is rounded up to a power of two.
    explicit SpscRing(size_t capacity) {
        size_t c = 1;
        while (c < capacity)
            c <<= 1;
        m_buf.resize(c);
        m_mask = c - 1;
    }
    bool push(const T& v) noexcept {
        const size_t h = m_head.load(std::memory_order_relaxed);
        if (h - m_tail.load(std::memory_order_acquire) > m_mask) {
            m_dropped.fetch_add(1, std::memory_order_relaxed);
            return false;
        }
        m_buf[h & m_mask] = v;
        m_head.store(h + 1, std::memory_order_release);
        return true;
    }
    bool pop(T& out) noexcept {
        const size_t t = m_tail.load(std::memory_order_relaxed);
        if (t == m_head.load(std::memory_order_acquire)) return false;
        out = m_buf[t & m_mask];
        m_tail.store(t + 1, std::memory_order_release);
        return true;
    }
    uint64_t dropped() const noexcept { return m_dropped.load(std::memory_order_relaxed); }
    size_t capacity() const { return m_buf.size(); }

private:
    std::vector<T> m_buf;
    size_t m_mask = 0;
    alignas(64) std::atomic<size_t> m_head{0};
    alignas(64) std::atomic<size_t> m_tail{0};
    std::atomic<uint64_t> m_dropped{0};
};

} // namespace viscera::haptics
