// SeqLock and SpscRing under concurrent use: readers never see a torn value, the ring keeps
// order and counts what it drops instead of blocking.
#include "haptics/lockfree.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <thread>

using namespace viscera::haptics;

namespace {
struct Payload {
    std::array<int64_t, 24> v{}; ///< every element equals the write count: a torn read mixes counts
};
} // namespace

TEST(SeqLock, ReadersNeverSeeATornValue) {
    SeqLock<Payload> lock;
    std::atomic<bool> done{false};
    std::atomic<int64_t> torn{0}, reads{0};
    std::thread reader([&] {
        int64_t last = 0;
        while (!done.load()) {
            const Payload p = lock.read();
            for (int64_t x : p.v)
                torn += x != p.v[0];
            torn += p.v[0] < last; // never goes back in time
            last = p.v[0];
            ++reads;
        }
    });
    // The reader is running before the writes start (else, on a busy machine, all the writes could
    // be over before its first read).
    while (reads.load() == 0)
        std::this_thread::yield();
    for (int64_t k = 1; k <= 200000; ++k) {
        Payload p;
        p.v.fill(k);
        lock.write(p);
    }
    done = true;
    reader.join();
    EXPECT_EQ(torn.load(), 0);
    EXPECT_GT(reads.load(), 0);
    EXPECT_EQ(lock.read().v[5], 200000);
    EXPECT_EQ(lock.writes(), 200000u);
}

TEST(SpscRing, KeepsOrderAcrossThreadsAndCountsDrops) {
    SpscRing<int64_t> ring(1000);
    EXPECT_EQ(ring.capacity(), 1024u);
    std::atomic<bool> done{false};
    std::vector<int64_t> got;
    std::thread consumer([&] {
        int64_t x;
        while (true) {
            const bool finished = done.load();
            while (ring.pop(x))
                got.push_back(x);
            if (finished) break;
        }
    });
    int64_t pushed = 0;
    for (int64_t k = 0; k < 300000; ++k)
        pushed += ring.push(k);
    done = true;
    consumer.join();
    EXPECT_EQ(int64_t(got.size()), pushed);
    EXPECT_EQ(uint64_t(300000 - pushed), ring.dropped());
    for (size_t i = 1; i < got.size(); ++i)
        ASSERT_LT(got[i - 1], got[i]);
    SpscRing<int> small(2);
    EXPECT_TRUE(small.push(1));
    EXPECT_TRUE(small.push(2));
    EXPECT_FALSE(small.push(3));
    EXPECT_EQ(small.dropped(), 1u);
}
