#pragma once
/// The soak [issue 19 item 4]: cases run back to back in one process for a given wall time, each
/// pass loaded afresh from its package (so loading and tearing down are soaked too), with a line
/// per interval: frames, all finite, energy against the case's first pass, resident memory.
#include "case/trust.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace viscera::player {

struct SoakCase {
    std::string path;   ///< .vcase
    std::string device; ///< device spec, empty: none (replay:… or scripted:…; lockstep)
    int frames = 300;   ///< per pass
};

struct SoakOptions {
    double seconds = 3600;        ///< wall time to run
    double lineSeconds = 60;      ///< one line per interval
    double energyTolerance = 0.1; ///< a pass's largest energy may exceed its case's first by this share
    vcase::TrustPolicy trust;     ///< which packages may run (loadCase)
};

struct SoakLine {
    int index = 0;         ///< 1, 2, …
    double wall_s = 0;     ///< since the start
    int64_t frames = 0;    ///< this interval
    int passes = 0;        ///< passes finished this interval
    bool allFinite = true; ///< every frame of those passes
    double maxEnergyJ = 0; ///< largest total energy in those passes
    bool energyBounded = true;
    double rssMiB = 0; ///< resident memory at the line
};

struct SoakResult {
    std::vector<SoakLine> lines;
    int64_t frames = 0;
    int passes = 0;
    std::vector<double> firstEnergyJ; ///< per case: the largest energy of its first pass
    std::vector<std::string> errors;  ///< a broken invariant, an unbounded energy, a failed load
    bool ok() const { return errors.empty(); }
    /// Resident memory growth from the line at `fromLine` (1-based; the first line when there are
    /// fewer) to the last, relative; 0 with fewer than two lines.
    double rssGrowth(int fromLine) const;
};

/// Resident set size of this process now, MiB (/proc/self/status VmRSS; 0 where unreadable).
double residentMiB();

/// Runs the soak; `line` is called for each interval as it ends (may be empty). Every case is
/// loaded once before the start, so a broken case is refused (viscera::InputError) before any
/// time is spent; device specs are parsed then too.
SoakResult runSoak(const std::vector<SoakCase>& cases, const SoakOptions& options,
                   const std::function<void(const SoakLine&)>& line);

nlohmann::json soakJson(const SoakResult& r, const std::vector<SoakCase>& cases);

} // namespace viscera::player
