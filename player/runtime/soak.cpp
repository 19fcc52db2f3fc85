#include "runtime/soak.hpp"

#include "haptics/device_spec.hpp"
#include "runtime/session.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace viscera::player {

double residentMiB() {
    std::ifstream in("/proc/self/status");
    std::string key;
    while (in >> key) {
        if (key == "VmRSS:") {
            double kib = 0;
            in >> kib;
            return kib / 1024.0;
        }
        std::string rest;
        std::getline(in, rest);
    }
    return 0;
}

double SoakResult::rssGrowth(int fromLine) const {
    if (lines.size() < 2) return 0;
    const size_t from = std::clamp<size_t>(static_cast<size_t>(std::max(fromLine, 1)) - 1, 0, lines.size() - 2);
    const double a = lines[from].rssMiB, b = lines.back().rssMiB;
    return a > 0 ? (b - a) / a : 0;
}

SoakResult runSoak(const std::vector<SoakCase>& cases, const SoakOptions& options,
                   const std::function<void(const SoakLine&)>& line) {
    if (cases.empty()) throw InputError("soak: no case given");
    for (const SoakCase& c : cases) { // refused before any time is spent
        (void)loadCase(c.path, options.trust);
        if (!c.device.empty()) (void)haptics::parseDeviceSpec(c.device);
    }
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    auto since = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
    SoakResult r;
    r.firstEnergyJ.assign(cases.size(), -1);
    SoakLine cur;
    cur.index = 1;
    std::atomic<bool> stop{false};
    auto flush = [&](double at) {
        cur.wall_s = at;
        cur.rssMiB = residentMiB();
        r.lines.push_back(cur);
        if (line) line(cur);
        const int next = cur.index + 1;
        cur = SoakLine{};
        cur.index = next;
    };
    for (size_t k = 0; since() < options.seconds; k = (k + 1) % cases.size()) {
        const SoakCase& c = cases[k];
        LoadedCase loaded;
        try {
            loaded = loadCase(c.path, options.trust);
        } catch (const std::exception& e) {
            r.errors.push_back(std::string("pass ") + std::to_string(r.passes + 1) + ": " + e.what());
            break;
        }
        std::unique_ptr<haptics::Device> dev;
        if (!c.device.empty()) dev = haptics::openDevice(haptics::parseDeviceSpec(c.device));
        RunOptions o;
        o.frames = c.frames;
        o.device = dev.get();
        o.deviceSpec = c.device;
        o.stop = &stop;
        const double deadline = options.seconds;
        o.progress = [&](int, int) {
            if (since() >= deadline) stop = true; // the soak ends mid-pass at its time
        };
        const SessionResult s = runSession(loaded, o);
        ++r.passes;
        ++cur.passes;
        r.frames += static_cast<int64_t>(s.frames.size());
        cur.frames += static_cast<int64_t>(s.frames.size());
        const bool finite = s.invariants.allFinite && std::isfinite(s.invariants.maxEnergy);
        cur.allFinite = cur.allFinite && finite;
        cur.maxEnergyJ = std::max(cur.maxEnergyJ, s.invariants.maxEnergy);
        for (const std::string& e : s.errors)
            r.errors.push_back(c.path + ": pass " + std::to_string(r.passes) + ": " + e);
        if (!finite) r.errors.push_back(c.path + ": pass " + std::to_string(r.passes) + ": a non-finite state");
        const bool complete = static_cast<int>(s.frames.size()) == c.frames;
        if (r.firstEnergyJ[k] < 0 && complete) {
            r.firstEnergyJ[k] = s.invariants.maxEnergy;
        } else if (r.firstEnergyJ[k] >= 0) {
            const double bound = r.firstEnergyJ[k] + options.energyTolerance * std::abs(r.firstEnergyJ[k]) + 1e-9;
            if (!(s.invariants.maxEnergy <= bound)) {
                cur.energyBounded = false;
                char msg[200];
                std::snprintf(msg, sizeof msg, ": pass %d: largest energy %.4g J above %.4g J (first pass + %.0f%%)",
                              r.passes, s.invariants.maxEnergy, r.firstEnergyJ[k], 100 * options.energyTolerance);
                r.errors.push_back(c.path + msg);
            }
        }
        if (!r.errors.empty() && !s.ok()) break;
        const double at = since();
        while (at >= cur.index * options.lineSeconds && at < options.seconds)
            flush(cur.index * options.lineSeconds);
    }
    if (cur.passes > 0 || r.lines.empty()) flush(since());
    return r;
}

nlohmann::json soakJson(const SoakResult& r, const std::vector<SoakCase>& cases) {
    using nlohmann::json;
    json lines = json::array();
    for (const SoakLine& l : r.lines)
        lines.push_back({{"line", l.index},
                         {"wall_s", l.wall_s},
                         {"frames", l.frames},
                         {"passes", l.passes},
                         {"all_finite", l.allFinite},
                         {"max_energy_j", l.maxEnergyJ},
                         {"energy_bounded", l.energyBounded},
                         {"rss_mib", l.rssMiB}});
    json cs = json::array();
    for (size_t k = 0; k < cases.size(); ++k)
        cs.push_back({{"case", cases[k].path},
                      {"device", cases[k].device},
                      {"frames_per_pass", cases[k].frames},
                      {"first_pass_max_energy_j", r.firstEnergyJ[k]}});
    return {{"cases", cs},        {"lines", lines},     {"frames", r.frames},
            {"passes", r.passes}, {"errors", r.errors}, {"rss_growth_from_line_5", r.rssGrowth(5)}};
}

} // namespace viscera::player
