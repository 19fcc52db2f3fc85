#include "sim/xpbd/detail/engine.hpp"

#include "sim/util/cpu_relax.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace viscera::sim::detail {
namespace {
/// Chunks: at least kMinChunkPacks packs (~1 µs of work), at most kChunksPerThread per thread and
/// colour (claiming a chunk costs an atomic increment; smaller chunks balance the threads better
/// at the end of each colour).
constexpr size_t kMinChunkPacks = 4;
constexpr size_t kChunksPerThread = 16;
constexpr size_t kChunkParticles = 1024;
/// A colour with fewer packs than this (a few µs of work) is swept by one thread together with
/// the small colours next to it, in colour order: the same result as a phase per colour, minus
/// the barriers between them (the greedy colouring leaves a tail of such colours in every stage).
constexpr size_t kSerialColourPacks = 48;
} // namespace

void Block::arrange(const std::vector<int32_t>& colourOfUnit, int colours) {
    std::vector<std::vector<int32_t>> byColour(colours);
    for (size_t u = 0; u < colourOfUnit.size(); ++u)
        byColour[colourOfUnit[u]].push_back(static_cast<int32_t>(u));
    std::vector<int32_t> slots;
    m_colourStart.assign(colours + 1, 0);
    for (int c = 0; c < colours; ++c) {
        slots.insert(slots.end(), byColour[c].begin(), byColour[c].end());
        while (slots.size() % 4)
            slots.push_back(-1);
        m_colourStart[c + 1] = slots.size() / 4;
    }
    build(slots);
}

int32_t Engine::addParticles(const std::vector<Vec3>& x, const std::vector<double>& m,
                             const std::vector<uint8_t>& fixed) {
    const auto first = static_cast<int32_t>(particleCount());
    for (size_t i = 0; i < x.size(); ++i) {
        xw.insert(xw.end(), {x[i].x(), x[i].y(), x[i].z(), (fixed[i] || !(m[i] > 0)) ? 0.0 : 1.0 / m[i]});
        v.push_back(Vec3::Zero());
        mass.push_back(m[i]);
    }
    return first;
}

void Engine::colour() {
    const size_t n = particleCount();
    std::vector<std::vector<int32_t>> colourOf(blocks.size());
    int32_t p[kMaxUnitParticles];
    m_colours = 0;
    int maxStage = 0;
    for (const auto& b : blocks)
        maxStage = std::max(maxStage, b->stage());
    for (int stage = 0; stage <= maxStage; ++stage) {
        const int base = m_colours;
        int words = 1;
        std::vector<uint64_t> used(n * words, 0);
        for (size_t b = 0; b < blocks.size(); ++b) {
            if (blocks[b]->stage() != stage) continue;
            colourOf[b].resize(blocks[b]->unitCount());
            for (size_t u = 0; u < colourOf[b].size(); ++u) {
                const int np = blocks[b]->unitParticles(u, p);
                int found = -1;
                while (found < 0) {
                    for (int wd = 0; wd < words && found < 0; ++wd) {
                        uint64_t taken = 0;
                        for (int k = 0; k < np; ++k)
                            taken |= used[static_cast<size_t>(p[k]) * words + wd];
                        if (~taken) found = wd * 64 + __builtin_ctzll(~taken);
                    }
                    if (found < 0) { // every colour so far is taken around this unit: widen the sets
                        std::vector<uint64_t> wider(n * (words + 1), 0);
                        for (size_t i = 0; i < n; ++i)
                            std::copy_n(used.begin() + i * words, words, wider.begin() + i * (words + 1));
                        used.swap(wider);
                        ++words;
                    }
                }
                for (int k = 0; k < np; ++k)
                    used[static_cast<size_t>(p[k]) * words + found / 64] |= uint64_t(1) << (found % 64);
                colourOf[b][u] = base + found;
                m_colours = std::max(m_colours, base + found + 1);
            }
        }
    }
    m_colourPacks.assign(m_colours, 0);
    for (size_t b = 0; b < blocks.size(); ++b) {
        blocks[b]->arrange(colourOf[b], m_colours);
        for (int c = 0; c < m_colours; ++c)
            m_colourPacks[c] += blocks[b]->colourEnd(c) - blocks[b]->colourBegin(c);
    }
}

namespace {

/// Returns once a ≥ target: spins briefly, then yields the core (the thread we wait for may be
/// queued behind us on a busy machine), then sleeps on the futex.
void waitAtLeast(const std::atomic<uint32_t>& a, uint32_t target) {
    for (int i = 0; i < 256; ++i) {
        if (a.load(std::memory_order_acquire) >= target) return;
        cpuRelax();
    }
    for (int i = 0; i < 64; ++i) {
        if (a.load(std::memory_order_acquire) >= target) return;
        std::this_thread::yield();
    }
    for (;;) {
        const uint32_t seen = a.load(std::memory_order_acquire);
        if (seen >= target) return;
        a.wait(seen, std::memory_order_acquire);
    }
}

} // namespace

int Engine::usefulThreads(int threads) const {
    if (threads <= 1) return 1;
    size_t most = 1;
    for (size_t packs : m_colourPacks)
        most = std::max(most, packs / kMinChunkPacks);
    return static_cast<int>(std::min<size_t>(threads, most));
}

template <class Fn> void Engine::forColourChunk(int c, uint32_t chunk, uint32_t chunks, const Fn& fn) {
    const size_t total = m_colourPacks[c];
    const size_t gb = total * chunk / chunks, ge = total * (chunk + 1) / chunks;
    size_t offset = 0;
    for (const auto& b : blocks) {
        const size_t bb = b->colourBegin(c), count = b->colourEnd(c) - bb;
        const size_t lo = std::max(gb, offset), hi = std::min(ge, offset + count);
        if (lo < hi) fn(*b, bb + (lo - offset), bb + (hi - offset));
        offset += count;
        if (offset >= ge) break;
    }
}

void Engine::solveColourChunk(int c, uint32_t chunk, uint32_t chunks, const SolveContext& ctx) {
    forColourChunk(c, chunk, chunks, [&](Block& b, size_t pb, size_t pe) { b.solve(pb, pe, ctx); });
}

void Engine::forceColourChunk(int c, uint32_t chunk, uint32_t chunks) {
    forColourChunk(c, chunk, chunks, [&](const Block& b, size_t pb, size_t pe) {
        b.addMultiplierForces(pb, pe, xw.data(), m_force.data());
    });
}

void Engine::correctParticles(uint32_t chunk) {
    const size_t n = particleCount();
    const size_t b = size_t(chunk) * kChunkParticles, e = std::min(n, b + kChunkParticles);
    for (size_t i = b; i < e; ++i) {
        double* p = xw.data() + 4 * i;
        double* f = m_force.data() + 3 * i;
        if (p[3] != 0)
            for (int r = 0; r < 3; ++r)
                p[r] = m_xTilde[i][r] + p[3] * f[r];
        f[0] = f[1] = f[2] = 0;
    }
}

uint32_t Engine::colourChunks(int c, int threads) const {
    return static_cast<uint32_t>(std::clamp<size_t>(m_colourPacks[c] / kMinChunkPacks, 1, kChunksPerThread * threads));
}

void Engine::appendCorrectionPhases(int threads) {
    for (int c = 0; c < m_colours; ++c) {
        Phase ph{c, c, false, false, false, colourChunks(c, threads)};
        ph.forces = true;
        m_phases.push_back(ph);
    }
    m_phases.push_back({kCorrect, -1, false, false, false,
                        static_cast<uint32_t>((particleCount() + kChunkParticles - 1) / kChunkParticles)});
}

bool Engine::cutOutsideHookRange() {
    m_outside.clear();
    const size_t n = particleCount(), e = std::min(hookEnd, n), b = std::min(hookFirst, e);
    if (b == 0 && e == n) return false;
    for (auto [lo, hi] : {std::pair{size_t(0), b}, std::pair{e, n}})
        for (size_t i = lo; i < hi; i += kChunkParticles)
            m_outside.push_back({i, std::min(hi, i + kChunkParticles)});
    return true;
}

void Engine::buildSchedule(Schedule kind, const XpbdSettings* s, int threads) {
    m_phases.clear();
    const auto particleChunks = static_cast<uint32_t>((particleCount() + kChunkParticles - 1) / kChunkParticles);
    auto colourPhases = [&](bool first, bool last) {
        for (int c = 0; c < m_colours; ++c) {
            Phase ph{c, c, first, last, false, colourChunks(c, threads)};
            if (m_colourPacks[c] < kSerialColourPacks) {
                ph.chunks = 1;
                while (ph.lastColour + 1 < m_colours && m_colourPacks[ph.lastColour + 1] < kSerialColourPacks)
                    ++ph.lastColour;
                c = ph.lastColour;
            }
            m_phases.push_back(ph);
        }
    };
    if (kind == Schedule::Sweep) {
        colourPhases(false, false);
    } else if (kind == Schedule::Correction) {
        appendCorrectionPhases(threads);
    } else {
        const bool hooks = iterationHook && iterationHookActive;
        const bool tail = hooks && cutOutsideHookRange();
        m_phases.push_back({kPredictOnly, -1, false, false, true, particleChunks});
        for (int sub = 0; sub < s->substeps; ++sub) {
            for (int it = 0; it < s->iterations; ++it) {
                // The correction reads the multipliers, so they are kept after the last sweep too.
                colourPhases(it == 0, it + 1 == s->iterations && !s->primalCorrection);
                if (s->primalCorrection) appendCorrectionPhases(threads);
                if (hooks && !(tail && it + 1 == s->iterations)) {
                    Phase ph{kHook, -1, false, false, false, 1};
                    ph.substep = sub;
                    ph.iteration = it;
                    m_phases.push_back(ph);
                }
            }
            if (tail) {
                Phase ph{
                    kHookTail, -1, false, false, sub + 1 < s->substeps, static_cast<uint32_t>(1 + m_outside.size())};
                ph.substep = sub;
                ph.iteration = s->iterations - 1;
                m_phases.push_back(ph);
            } else if (hooks) {
                // End of substep split in two around the velocity pass of the hook.
                m_phases.push_back({-1, -1, false, false, false, particleChunks});
                Phase ph{kHook, -1, false, false, false, 1};
                ph.substep = sub;
                ph.iteration = s->iterations;
                m_phases.push_back(ph);
                if (sub + 1 < s->substeps) m_phases.push_back({kPredictOnly, -1, false, false, true, particleChunks});
            } else {
                m_phases.push_back({-1, -1, false, false, sub + 1 < s->substeps, particleChunks});
            }
        }
    }
    m_phaseStart.assign(m_phases.size() + 1, 0);
    for (size_t p = 0; p < m_phases.size(); ++p)
        m_phaseStart[p + 1] = m_phaseStart[p] + m_phases[p].chunks;
}

template <class RunChunk> void Engine::execute(int threads, WorkerPool* pool, const RunChunk& run) {
    if (threads <= 1) {
        for (size_t p = 0; p < m_phases.size(); ++p)
            for (uint32_t j = 0; j < m_phases[p].chunks; ++j)
                run(m_phases[p], j, 0);
        return;
    }
    const size_t cursors = m_phases.size() * threads;
    if (m_cursorCount < cursors) {
        m_cursors = std::make_unique<Cursor[]>(cursors);
        m_cursorCount = cursors;
    }
    for (size_t i = 0; i < cursors; ++i)
        m_cursors[i].claimed.store(0, std::memory_order_relaxed);
    m_doneChunks.store(0, std::memory_order_relaxed);
    const auto job = [&](int tid) {
        for (size_t p = 0; p < m_phases.size(); ++p) {
            waitAtLeast(m_doneChunks, m_phaseStart[p]);
            // Chunks of a phase are split into one group per thread (the same region of the
            // mesh in every colour, so particles stay in that thread's cache); a thread takes
            // its own group first, then helps with the others.
            const uint32_t n = m_phases[p].chunks;
            uint32_t done = 0;
            for (int k = 0; k < threads; ++k) {
                const int g = (tid + k) % threads;
                const uint32_t gb = n * g / threads, size = n * (g + 1) / threads - gb;
                std::atomic<uint32_t>& claimed = m_cursors[p * threads + g].claimed;
                while (claimed.load(std::memory_order_relaxed) < size) {
                    const uint32_t i = claimed.fetch_add(1, std::memory_order_relaxed);
                    if (i >= size) break;
                    run(m_phases[p], gb + i, tid);
                    ++done;
                }
            }
            if (done) {
                m_doneChunks.fetch_add(done, std::memory_order_release);
                m_doneChunks.notify_all();
            }
        }
    };
    pool->run(threads, job);
}

// Particles [b, e): the end of the substep (velocity from the move, speed clamp, damping) and/or
// the start of the next (remember x, predict x̃ = x + h (v + h g)).
void Engine::particlePass(size_t b, size_t e, bool end, bool next, int tid, const SubstepKinematics& k) {
    double* const x = xw.data();
    const bool scaledGravity = !gravityScale.empty();
    for (size_t i = b; i < e; ++i) {
        double* p = x + 4 * i;
        Vec3& vi = v[i];
        if (end) {
            if (p[3] == 0) {
                vi.setZero();
            } else {
                Vec3 vel = (Vec3(p[0], p[1], p[2]) - m_prev[i]) * k.invH;
                const double speed2 = vel.squaredNorm();
                if (speed2 > k.vmax2) {
                    vel *= k.vmax / std::sqrt(speed2);
                    const Vec3 xi = m_prev[i] + k.h * vel;
                    p[0] = xi.x();
                    p[1] = xi.y();
                    p[2] = xi.z();
                    ++m_clamps[tid];
                }
                vi = k.decay * vel;
            }
        }
        if (!next) continue;
        m_prev[i] = Vec3(p[0], p[1], p[2]);
        if (p[3] != 0) {
            if (scaledGravity)
                vi += gravityScale[i] * k.hg;
            else
                vi += k.hg;
            p[0] += k.h * vi.x();
            p[1] += k.h * vi.y();
            p[2] += k.h * vi.z();
        }
        if (k.keepPrediction) m_xTilde[i] = Vec3(p[0], p[1], p[2]);
    }
}

StepStats Engine::frame(const XpbdSettings& s, WorkerPool* pool) {
    StepStats st;
    const int substeps = s.substeps;
    const double h = s.dt / substeps;
    const double h2inv = 1.0 / (h * h), invH = 1.0 / h;
    const double decay = std::exp(-s.damping * h);
    const double vmax = s.maxSpeed, vmax2 = vmax * vmax;
    const Vec3 hg = h * s.gravity;
    const size_t n = particleCount();
    m_frameStart = xw;
    m_v0 = v;
    m_prev.resize(n);
    if (s.primalCorrection) {
        m_xTilde.resize(n);
        m_force.assign(3 * n, 0.0);
    }
    const int threads = usefulThreads(pool ? std::min(s.threads, pool->size()) : 1);
    m_clamps.assign(threads, 0);
    m_hookFailed = false;
    buildSchedule(Schedule::Frame, &s, threads);
    double* const x = xw.data();
    const SubstepKinematics k{h, invH, decay, vmax, vmax2, hg, s.primalCorrection};
    auto callHook = [&](int substep, int iteration) {
        XpbdParticles view(x, v.data(), n);
        const XpbdIterationInfo info{substep, iteration, substeps, s.iterations, h, iteration == s.iterations};
        try {
            iterationHook(view, info);
        } catch (...) {
            m_hookFailed = true;
        }
    };
    execute(threads, pool, [&](const Phase& ph, uint32_t chunk, int tid) {
        if (ph.colour >= 0) {
            if (ph.forces)
                forceColourChunk(ph.colour, chunk, ph.chunks);
            else
                for (int c = ph.colour; c <= ph.lastColour; ++c)
                    solveColourChunk(c, chunk, ph.chunks, SolveContext{x, h2inv, ph.first, ph.last});
            return;
        }
        if (ph.colour == kCorrect) {
            correctParticles(chunk);
            return;
        }
        if (ph.colour == kHook) {
            callHook(ph.substep, ph.iteration);
            return;
        }
        if (ph.colour == kHookTail && chunk > 0) {
            particlePass(m_outside[chunk - 1].first, m_outside[chunk - 1].second, true, ph.predictNext, tid, k);
            return;
        }
        if (ph.colour == kHookTail) { // the hook's particles, in the order of the phases it stands for
            const size_t e = std::min(hookEnd, n), b = std::min(hookFirst, e);
            callHook(ph.substep, ph.iteration);
            particlePass(b, e, true, false, tid, k);
            callHook(ph.substep, s.iterations);
            particlePass(b, e, false, ph.predictNext, tid, k);
            return;
        }
        const size_t b = size_t(chunk) * kChunkParticles, e = std::min(n, b + kChunkParticles);
        particlePass(b, e, ph.colour != kPredictOnly, ph.predictNext, tid, k);
    });

    st.substeps = substeps;
    st.iterations = s.iterations;
    for (int c : m_clamps)
        st.speedClamps += c;
    if (m_hookFailed) st.finite = false;
    for (size_t i = 0; i < n && st.finite; ++i) {
        const double* p = x + 4 * i;
        const Vec3 xi(p[0], p[1], p[2]);
        if (!xi.allFinite() || !v[i].allFinite()) {
            st.finite = false;
            break;
        }
        const double* p0 = m_frameStart.data() + 4 * i;
        st.maxDisplacement = std::max(st.maxDisplacement, (xi - Vec3(p0[0], p0[1], p0[2])).norm());
    }
    if (!st.finite) {
        xw = m_frameStart;
        v = m_v0;
        st.maxDisplacement = 0;
    }
    return st;
}

double Engine::energy(int threads, WorkerPool* pool) {
    // Parts of at least kEnergyPartUnits units, at most kEnergyParts per block: fixed by the
    // blocks alone, so the sum (in part order) is the same for any number of threads.
    // The blocks and their units are fixed once coloured (a cut deactivates units), so the parts
    // are cut once.
    constexpr size_t kEnergyPartUnits = 1024, kEnergyParts = 16;
    if (m_energyParts.empty())
        for (size_t b = 0; b < blocks.size(); ++b) {
            const size_t units = blocks[b]->unitCount();
            const size_t parts = std::clamp<size_t>(units / kEnergyPartUnits, 1, kEnergyParts);
            for (size_t k = 0; k < parts; ++k)
                m_energyParts.push_back({b, units * k / parts, units * (k + 1) / parts});
        }
    m_energySums.assign(m_energyParts.size(), 0.0);
    m_phases.assign(1, Phase{kEnergy, -1, false, false, false, static_cast<uint32_t>(m_energyParts.size())});
    m_phaseStart = {0, m_phases[0].chunks};
    const int t = usefulThreads(pool ? std::min(threads, pool->size()) : 1);
    execute(t, pool, [&](const Phase&, uint32_t chunk, int) {
        const EnergyPart& p = m_energyParts[chunk];
        m_energySums[chunk] = blocks[p.block]->energy(xw.data(), p.begin, p.end);
    });
    double e = 0;
    for (double s : m_energySums)
        e += s;
    return e;
}

bool Engine::supportsPrimalCorrection() const {
    for (const auto& b : blocks)
        if (!b->addMultiplierForces(0, 0, xw.data(), nullptr)) return false;
    return true;
}

double Engine::primalCorrection(const std::vector<Vec3>& xTilde, int threads, WorkerPool* pool) {
    const int t = usefulThreads(pool ? std::min(threads, pool->size()) : 1);
    buildSchedule(Schedule::Correction, nullptr, t);
    m_xTilde = xTilde;
    m_force.assign(3 * particleCount(), 0.0);
    const auto t0 = std::chrono::steady_clock::now();
    execute(t, pool, [&](const Phase& ph, uint32_t chunk, int) {
        if (ph.colour >= 0)
            forceColourChunk(ph.colour, chunk, ph.chunks);
        else
            correctParticles(chunk);
    });
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double Engine::sweep(bool first, double h2inv, int threads, WorkerPool* pool) {
    const int t = usefulThreads(pool ? std::min(threads, pool->size()) : 1);
    buildSchedule(Schedule::Sweep, nullptr, t);
    double* const x = xw.data();
    const auto t0 = std::chrono::steady_clock::now();
    execute(t, pool, [&](const Phase& ph, uint32_t chunk, int) {
        for (int c = ph.colour; c <= ph.lastColour; ++c)
            solveColourChunk(c, chunk, ph.chunks, SolveContext{x, h2inv, first, false});
    });
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace viscera::sim::detail
