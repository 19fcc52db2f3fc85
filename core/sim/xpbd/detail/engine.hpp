#pragma once
/// The XPBD engine behind XpbdSolver and XpbdSystem (private to sim/xpbd).
///
/// Particles of every body live in one array, four doubles each (x, y, z in metres and the
/// inverse mass in 1/kg, 0 for a fixed particle), 64-byte aligned, so that a SIMD kernel loads a
/// particle with one instruction. Constraints live in blocks (one per kind and body); a block's
/// unit is what one solve call updates at once (a tet with its constraints, a triangle, a tie).
/// All units of all blocks are greedy-coloured by shared particles; a colour's units are
/// independent, so a colour is split into chunks that run in parallel without locks, and the
/// result does not depend on the number of threads. Inside each block the units of a colour are
/// laid out in packs of four (padding slots marked), the granularity of chunks and SIMD lanes.
#include "sim/xpbd/detail/thread_pool.hpp"
#include "sim/xpbd/xpbd_settings.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

namespace viscera::sim::detail {

template <class T, std::size_t Align> struct AlignedAllocator {
    using value_type = T;
    AlignedAllocator() = default;
    template <class U> AlignedAllocator(const AlignedAllocator<U, Align>&) {}
    template <class U> struct rebind { using other = AlignedAllocator<U, Align>; };
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(Align))); }
    void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t(Align)); }
    friend bool operator==(const AlignedAllocator&, const AlignedAllocator&) { return true; }
};

using ParticleArray = std::vector<double, AlignedAllocator<double, 64>>;

inline Vec3 particlePosition(const double* xw, int32_t i) {
    const double* p = xw + 4 * static_cast<size_t>(i);
    return Vec3(p[0], p[1], p[2]);
}
inline double particleInvMass(const double* xw, int32_t i) {
    return xw[4 * static_cast<size_t>(i) + 3];
}
inline void moveParticle(double* xw, int32_t i, const Vec3& d) {
    double* p = xw + 4 * static_cast<size_t>(i);
    p[0] += d.x();
    p[1] += d.y();
    p[2] += d.z();
}

struct SolveContext {
    double* xw;   ///< particle array
    double h2inv; ///< 1/h², 1/s²
    bool first;   ///< first iteration of a substep: multipliers start from 0 [A eq. 4.43]
    bool last;    ///< last iteration of a substep: the multipliers need not be kept
};

inline constexpr int kMaxUnitParticles = 8;

class Block {
public:
    virtual ~Block() = default;
    virtual size_t unitCount() const = 0;
    /// Particles of unit u into out (at most kMaxUnitParticles); returns their count.
    virtual int unitParticles(size_t u, int32_t* out) const = 0;
    /// Solves the units of packs [packBegin, packEnd) (all of one colour) once, in place.
    virtual void solve(size_t packBegin, size_t packEnd, const SolveContext& ctx) = 0;
    /// Stored energy (J) of units [unitBegin, unitEnd) at the particle positions; hard
    /// constraints count 0.
    virtual double energy(const double* xw, size_t unitBegin, size_t unitEnd) const = 0;
    /// Sweep order: all colours of stage 0 (elasticity), then stage 1 (strain limits), then
    /// stage 2 (couplings), so that limits and ties are the last word of every sweep.
    virtual int stage() const { return 0; }
    /// Adds Σ_j ∇C_j(x)ᵀ λ_j of the units of packs [packBegin, packEnd) (all of one colour, so
    /// no particle twice), at the particle positions of xw and the multipliers of the current
    /// substep, to f (3 per particle; kg·m, i.e. h² times a force). Returns false when the block
    /// does not support it (then the engine offers no primal correction). O(units).
    virtual bool addMultiplierForces(size_t /*packBegin*/, size_t /*packEnd*/, const double* /*xw*/,
                                     double* /*f*/) const {
        return false;
    }

    /// Dissection [A §5.3]: switches unit u on or off between frames. An inactive unit moves
    /// nothing, stores no energy and adds no multiplier force. Returns false (and changes
    /// nothing) when the block kind does not support it. O(1).
    virtual bool setUnitActive(size_t /*u*/, bool /*active*/) { return false; }
    /// Dissection shrinkage [A eq. 5.12]: replaces the rest inverse edge matrix Dm⁻¹ of unit u
    /// between frames (row-major; 9 doubles for a tet, 1/m, 4 for a triangle in its plane
    /// frame). Returns false when the block kind does not support it. O(1).
    virtual bool setUnitRestInverse(size_t /*u*/, const double* /*dmInv*/) { return false; }

    /// Lays the units out by colour (colourOfUnit: one entry per unit) in packs of four.
    void arrange(const std::vector<int32_t>& colourOfUnit, int colours);
    size_t packCount() const { return m_colourStart.empty() ? 0 : m_colourStart.back(); }
    size_t colourBegin(int c) const { return m_colourStart[c]; }
    size_t colourEnd(int c) const { return m_colourStart[c + 1]; }

protected:
    /// slots: four per pack, a unit index or −1 for padding, in colour order.
    virtual void build(const std::vector<int32_t>& slots) = 0;

private:
    std::vector<size_t> m_colourStart;
};

class Engine {
public:
    ParticleArray xw;         ///< 4 per particle: x, y, z (m), inverse mass (1/kg, 0 = fixed)
    std::vector<Vec3> v;      ///< velocities, m/s
    std::vector<double> mass; ///< kg (fixed particles keep theirs)
    /// Empty, or one per particle: the fraction of gravity it feels (m / (m + added inertia) for
    /// a node with selective inertia scaling, so that its weight stays m g).
    std::vector<double> gravityScale;
    std::vector<std::unique_ptr<Block>> blocks;
    /// Optional: called by frame() after every sweep (see XpbdIterationHook). Empty: frame()
    /// runs exactly the schedule it runs without hooks.
    XpbdIterationHook iterationHook;
    /// False: the next frames run without calling iterationHook, on the schedule without hooks
    /// (a frame in which no hook has anything to do: no tool near the tissue, nothing held).
    bool iterationHookActive = true;
    /// Particles [hookFirst, hookEnd) are all that iterationHook reads and writes (default:
    /// every particle). With a narrower range, each substep ends in one phase: one chunk runs
    /// the last iteration's hook, the end of the substep for those particles, the velocity-pass
    /// hook and their next prediction, while the other chunks end the substep of every other
    /// particle and predict the next in one pass (the same results as the phases one after the
    /// other, without three barriers and a second pass over the particles).
    size_t hookFirst = 0, hookEnd = SIZE_MAX;

    size_t particleCount() const { return mass.size(); }
    /// Appends particles (positions, masses, fixed flags; all the same size); returns the index
    /// of the first. Inverse mass: 0 when fixed or massless, else 1/m.
    int32_t addParticles(const std::vector<Vec3>& x, const std::vector<double>& m, const std::vector<uint8_t>& fixed);
    /// Greedy colouring of all units of all blocks by shared particles (stage by stage, each
    /// stage with its own colours), then arranges the blocks. Call once, after the last block is
    /// added.
    void colour();
    int colourCount() const { return m_colours; }
    /// Packs per colour, all blocks together.
    const std::vector<size_t>& colourPacks() const { return m_colourPacks; }

    /// One frame: substeps × (predict, iterations × colours, velocity update, speed clamp), with
    /// rollback of a non-finite result. Never throws.
    StepStats frame(const XpbdSettings& s, WorkerPool* pool);
    /// One sweep over all colours; returns its wall time in seconds.
    double sweep(bool first, double h2inv, int threads, WorkerPool* pool);
    /// Primal correction [A eq. 4.41, first row]: x ← x̃ + M⁻¹ Σ_j ∇C_j(x)ᵀ λ_j for every free
    /// particle, so that the primal residual g(x, λ) that XPBD's update drops is zero at the
    /// current gradients (fixed particles stay). xTilde: one per particle. Returns the wall time
    /// in seconds. Parallel like a sweep (colour by colour, bit-identical for any thread count);
    /// O(particles + units). Only when supportsPrimalCorrection().
    double primalCorrection(const std::vector<Vec3>& xTilde, int threads, WorkerPool* pool);
    /// Stored energy of every block (J), summed in a fixed order of fixed parts of each block, so
    /// the same for any thread count; the parts run in parallel like a sweep.
    double energy(int threads, WorkerPool* pool);
    /// True when every block supports the primal correction.
    bool supportsPrimalCorrection() const;
    /// Threads worth using (≤ threads): 1 when no colour is large enough to split.
    int usefulThreads(int threads) const;

private:
    /// A step of the schedule: a colour sweep (colour ≥ 0) or a particle pass (colour < 0: end of
    /// a substep and, when predictNext, start of the next; or, with colour == kPredictOnly, only
    /// the start of the first substep). Its work is cut into chunks (a colour: a few per thread;
    /// particles: kChunkParticles each), which are independent of each other, so the results do
    /// not depend on how the chunks are cut.
    struct Phase {
        int colour = 0;
        /// Colour sweep: the last colour of the phase (> colour: a run of small colours that one
        /// thread sweeps in order in one chunk, sparing the barriers between them).
        int lastColour = -1;
        bool first = false;       ///< colour sweep: first iteration of the substep
        bool last = false;        ///< colour sweep: last iteration of the substep
        bool predictNext = false; ///< particle pass: also start the next substep
        uint32_t chunks = 0;
        bool forces = false;            ///< colour pass of the primal correction: Σ ∇Cᵀλ into m_force
        int substep = 0, iteration = 0; ///< kHook: where in the frame
    };
    /// Chunk 0: the hooks' end of a substep (see hookFirst); chunk k > 0: the end of the substep
    /// and the next prediction of the particles of m_outside[k − 1].
    static constexpr int kHookTail = -5;
    static constexpr int kPredictOnly = -2;
    /// Particle pass of the primal correction: x = x̃ + w f, f = 0.
    static constexpr int kCorrect = -3;
    /// One chunk: the iteration hook (after the sweep, and the correction, of an iteration).
    static constexpr int kHook = -4;
    /// One chunk: the energy of m_energyParts[chunk] into m_energySums[chunk].
    static constexpr int kEnergy = -6;
    enum class Schedule { Frame, Sweep, Correction };
    /// s: needed for Schedule::Frame only.
    void buildSchedule(Schedule kind, const XpbdSettings* s, int threads);
    void appendCorrectionPhases(int threads);
    /// A frame's substep figures for the particle passes.
    struct SubstepKinematics {
        double h, invH, decay, vmax, vmax2;
        Vec3 hg;             ///< h · gravity
        bool keepPrediction; ///< primal correction: x̃ into m_xTilde
    };
    void particlePass(size_t b, size_t e, bool end, bool next, int tid, const SubstepKinematics& k);
    /// The chunks of m_outside; true when the hook's range leaves particles out (kHookTail).
    bool cutOutsideHookRange();
    /// Chunks of a phase of colour c: a few per thread, each at least kMinChunkPacks packs.
    uint32_t colourChunks(int c, int threads) const;
    void forceColourChunk(int c, uint32_t chunk, uint32_t chunks);
    void correctParticles(uint32_t chunk);
    template <class Fn> void forColourChunk(int c, uint32_t chunk, uint32_t chunks, const Fn& fn);
    /// Runs every chunk of m_phases in order: a phase starts when all chunks of the previous
    /// ones are done. Parallel: the chunks of a phase form one group per thread; a thread claims
    /// chunks of its own group, then of the others, from per-group atomic cursors, and adds its
    /// count to an atomic of finished chunks that the next phase waits on. A thread that the OS
    /// pauses therefore holds the others up only while it is inside a chunk. Serial: a plain
    /// loop over the same chunks.
    template <class RunChunk> void execute(int threads, WorkerPool* pool, const RunChunk& run);
    void solveColourChunk(int c, uint32_t chunk, uint32_t chunks, const SolveContext& ctx);

    std::vector<size_t> m_colourPacks;
    int m_colours = 0;
    std::vector<Phase> m_phases;
    std::vector<uint32_t> m_phaseStart; ///< first global chunk of each phase, plus the total
    struct alignas(64) Cursor {
        std::atomic<uint32_t> claimed{0};
    };
    std::unique_ptr<Cursor[]> m_cursors; ///< per phase and thread group: chunks claimed
    size_t m_cursorCount = 0;
    alignas(64) std::atomic<uint32_t> m_doneChunks{0};
    std::vector<Vec3> m_prev;
    std::vector<std::pair<size_t, size_t>> m_outside; ///< particle chunks outside the hook's range
    struct EnergyPart {
        size_t block, begin, end;
    };
    std::vector<EnergyPart> m_energyParts; ///< fixed parts of the blocks' units (see energy())
    std::vector<double> m_energySums;
    ParticleArray m_frameStart;
    std::vector<Vec3> m_v0;
    std::vector<int> m_clamps;   ///< per thread
    std::vector<double> m_force; ///< primal correction: Σ ∇Cᵀλ, 3 per particle (0 between uses)
    std::vector<Vec3> m_xTilde;  ///< prediction of the current substep (primal correction)
    bool m_hookFailed = false;   ///< the iteration hook threw during this frame
};

} // namespace viscera::sim::detail
