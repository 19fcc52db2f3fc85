#pragma once
/// A hint to the CPU inside a spin-wait loop (x86 `pause`, ARM `yield`, a no-op elsewhere): lets
/// the sibling hyper-thread run and saves power. Cost: a few to ~100 cycles, no system call.
#if defined(__x86_64__) || defined(__i386__) || defined(_M_X64) || defined(_M_IX86)
#include <immintrin.h>
#endif

namespace viscera::sim {

inline void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__) || defined(_M_X64) || defined(_M_IX86)
    _mm_pause();
#elif defined(__aarch64__) || defined(__arm__)
    __asm__ __volatile__("yield");
#endif
}

} // namespace viscera::sim
