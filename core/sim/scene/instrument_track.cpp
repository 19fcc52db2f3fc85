#include "sim/scene/instrument_track.hpp"

#include "sim/util/error.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace viscera::sim {
namespace {

constexpr const char* kHeader = "# viscera instrument track 1";

/// Empty when the keys follow the rules, else "keys[i].field: rule".
std::string checkKeys(const std::vector<InstrumentKey>& keys) {
    if (keys.empty()) return "keys: a track needs at least one key";
    for (size_t i = 0; i < keys.size(); ++i) {
        const InstrumentKey& k = keys[i];
        const std::string at = "keys[" + std::to_string(i) + "]";
        if (!std::isfinite(k.t) || k.t < 0) return at + ".t: must be finite and >= 0";
        if (i > 0 && !(k.t > keys[i - 1].t)) return at + ".t: times must strictly increase";
        if (!k.position.allFinite()) return at + ".position: must be finite";
        if (!k.direction.allFinite() || k.direction.norm() < 1e-9)
            return at + ".direction: must be finite and non-zero";
        if (!(k.jaw >= 0 && k.jaw <= 1)) return at + ".jaw: must be in [0, 1]";
    }
    return {};
}

} // namespace

InstrumentTrack::InstrumentTrack(std::vector<InstrumentKey> keys) : m_keys(std::move(keys)) {
    if (auto why = checkKeys(m_keys); !why.empty()) throw std::invalid_argument("sim::InstrumentTrack: " + why);
    for (InstrumentKey& k : m_keys)
        k.direction.normalize();
}

InstrumentTrack InstrumentTrack::parse(std::string_view text, const std::string& origin) {
    std::istringstream in{std::string(text)};
    std::string line;
    int lineNo = 0;
    std::vector<InstrumentKey> keys;
    auto fail = [&](const std::string& what) { throw InputError(origin + ":" + std::to_string(lineNo) + ": " + what); };
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (lineNo == 1) {
            if (line != kHeader) fail("header: the first line must be '" + std::string(kHeader) + "'");
            continue;
        }
        const size_t first = line.find_first_not_of(" \t");
        if (first == std::string::npos || line[first] == '#') continue;
        std::istringstream fields(line);
        double v[9];
        int n = 0;
        std::string tok;
        while (fields >> tok) {
            if (n == 9) fail("key: expected 9 numbers (t x y z dx dy dz jaw act), found more");
            char* end = nullptr;
            v[n] = std::strtod(tok.c_str(), &end);
            if (end == tok.c_str() || *end != '\0') fail("key: '" + tok + "' is not a number");
            ++n;
        }
        if (n != 9) fail("key: expected 9 numbers (t x y z dx dy dz jaw act), found " + std::to_string(n));
        InstrumentKey k;
        k.t = v[0];
        k.position = Vec3(v[1], v[2], v[3]);
        k.direction = Vec3(v[4], v[5], v[6]);
        k.jaw = v[7];
        if (v[8] != 0 && v[8] != 1) fail("act: must be 0 or 1");
        k.act = v[8] == 1;
        keys.push_back(k);
        std::vector<InstrumentKey> probe{keys.size() > 1 ? keys[keys.size() - 2] : k, k};
        if (keys.size() == 1) probe.pop_back();
        if (auto why = checkKeys(probe); !why.empty()) fail(why.substr(why.find('.') + 1));
    }
    if (lineNo == 0) {
        lineNo = 1;
        fail("header: the file is empty");
    }
    if (keys.empty()) fail("keys: a track needs at least one key");
    return InstrumentTrack(std::move(keys));
}

std::string InstrumentTrack::format() const {
    std::string out = std::string(kHeader) + "\n# t x y z dx dy dz jaw act\n";
    char buf[256];
    for (const InstrumentKey& k : m_keys) {
        std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %d\n", k.t, k.position.x(),
                      k.position.y(), k.position.z(), k.direction.x(), k.direction.y(), k.direction.z(), k.jaw,
                      k.act ? 1 : 0);
        out += buf;
    }
    return out;
}

InstrumentKey InstrumentTrack::sample(double t) const {
    if (m_keys.empty()) return {};
    if (!(t > m_keys.front().t)) return m_keys.front();
    if (t >= m_keys.back().t) return m_keys.back();
    size_t i = 1;
    while (m_keys[i].t <= t)
        ++i;
    const InstrumentKey& a = m_keys[i - 1];
    const InstrumentKey& b = m_keys[i];
    const double s = (t - a.t) / (b.t - a.t);
    InstrumentKey k;
    k.t = t;
    k.position = (1 - s) * a.position + s * b.position;
    Vec3 d = (1 - s) * a.direction + s * b.direction;
    k.direction = d.norm() > 1e-9 ? Vec3(d.normalized()) : a.direction;
    k.jaw = (1 - s) * a.jaw + s * b.jaw;
    k.act = a.act;
    return k;
}

} // namespace viscera::sim
