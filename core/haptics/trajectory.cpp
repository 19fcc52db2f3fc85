#include "haptics/trajectory.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace viscera::haptics {
namespace {

constexpr const char* kMagic = "# viscera-trajectory 1";
constexpr const char* kColumns = "t,arm,x,y,z,qw,qx,qy,qz,grip,buttons,pedals";
constexpr size_t kMaxSamples = 20'000'000;

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

} // namespace

Trajectory Trajectory::parse(std::string_view text, const std::string& origin) {
    static const char* names[] = {"t", "arm", "x", "y", "z", "qw", "qx", "qy", "qz", "grip", "buttons", "pedals"};
    Trajectory traj;
    size_t lineNo = 0, pos = 0;
    bool sawMagic = false, sawColumns = false;
    auto fail = [&](const std::string& what) -> void {
        throw InputError(origin + ": line " + std::to_string(lineNo) + ": " + what);
    };
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = trim(text.substr(pos, end - pos));
        pos = end + 1;
        ++lineNo;
        if (line.empty()) continue;
        if (!sawMagic) {
            if (line != kMagic)
                fail("the first line must be '" + std::string(kMagic) +
                     "' (not a trajectory file, or another version)");
            sawMagic = true;
            continue;
        }
        if (line.front() == '#') continue;
        if (!sawColumns) {
            if (line != kColumns) fail("the column header must be '" + std::string(kColumns) + "'");
            sawColumns = true;
            continue;
        }
        double v[12];
        size_t field = 0, p = 0;
        while (true) {
            size_t comma = line.find(',', p);
            std::string_view tok =
                trim(line.substr(p, comma == std::string_view::npos ? std::string_view::npos : comma - p));
            if (field >= 12) fail("has more than 12 fields");
            std::string s(tok);
            char* stop = nullptr;
            errno = 0;
            v[field] = s.empty() ? NAN : std::strtod(s.c_str(), &stop);
            if (s.empty() || stop != s.c_str() + s.size())
                fail(std::string("field '") + names[field] + "': not a number");
            if (!std::isfinite(v[field]) || errno == ERANGE)
                fail(std::string("field '") + names[field] + "': must be finite");
            ++field;
            if (comma == std::string_view::npos) break;
            p = comma + 1;
        }
        if (field != 12) fail("has " + std::to_string(field) + " fields, expected 12 (" + kColumns + ")");
        TrajectorySample s;
        s.t = v[0];
        if (s.t < 0) fail("field 't': must not be negative");
        if (v[1] != std::floor(v[1]) || v[1] < 0 || v[1] >= kMaxArms) fail("field 'arm': must be 0 or 1");
        const int arm = static_cast<int>(v[1]);
        for (int k = 2; k <= 4; ++k)
            if (std::abs(v[k]) > 10.0) fail(std::string("field '") + names[k] + "': must be within ±10 m");
        s.pose.position = Vec3(v[2], v[3], v[4]);
        Quat q(v[5], v[6], v[7], v[8]);
        const double n = q.norm();
        if (!(n > 0.9 && n < 1.1)) fail("fields 'qw'..'qz': the quaternion norm must be within 10% of 1");
        s.pose.orientation = q.normalized();
        if (v[9] < 0 || v[9] > M_PI) fail("field 'grip': must be in [0, pi] rad");
        s.grip = v[9];
        if (v[10] != std::floor(v[10]) || v[10] < 0 || v[10] > 4294967295.0)
            fail("field 'buttons': must be an unsigned 32-bit integer");
        s.buttons = static_cast<uint32_t>(v[10]);
        if (v[11] != std::floor(v[11]) || v[11] < 0 || v[11] > double(uint32_t(kPedalMask)))
            fail("field 'pedals': must be an integer in [0, 31]");
        s.pedals = static_cast<uint32_t>(v[11]);
        auto& a = traj.m_arms[arm];
        if (!a.empty() && !(s.t > a.back().t))
            fail("field 't': must increase from one sample of arm " + std::to_string(arm) + " to the next");
        if (a.size() + 1 > kMaxSamples) fail("more than 20,000,000 samples");
        a.push_back(s);
    }
    if (!sawMagic) throw InputError(origin + ": empty file (expected '" + std::string(kMagic) + "')");
    if (traj.m_arms[0].empty() && traj.m_arms[1].empty()) throw InputError(origin + ": contains no sample");
    return traj;
}

Trajectory Trajectory::load(const std::filesystem::path& path) {
    return parse(readFile(path), path.string());
}

std::string Trajectory::format() const {
    std::string out = std::string(kMagic) + "\n" + kColumns + "\n";
    char buf[512];
    for (int a = 0; a < kMaxArms; ++a)
        for (const auto& s : m_arms[a]) {
            const Vec3& x = s.pose.position;
            const Quat& q = s.pose.orientation;
            std::snprintf(buf, sizeof buf, "%.6f,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%u,%u\n", s.t, a, x.x(),
                          x.y(), x.z(), q.w(), q.x(), q.y(), q.z(), s.grip, s.buttons, s.pedals);
            out += buf;
        }
    return out;
}

void Trajectory::add(int arm, const TrajectorySample& s) {
    if (arm < 0 || arm >= kMaxArms)
        throw std::invalid_argument("haptics::Trajectory::add(): arm " + std::to_string(arm) + " is out of range");
    auto& a = m_arms[arm];
    if (!a.empty() && !(s.t > a.back().t))
        throw std::invalid_argument("haptics::Trajectory::add(): t " + std::to_string(s.t) + " does not increase");
    a.push_back(s);
}

int Trajectory::arms() const {
    for (int a = kMaxArms - 1; a >= 0; --a)
        if (!m_arms[a].empty()) return a + 1;
    return 0;
}

double Trajectory::duration() const {
    double d = 0;
    for (const auto& a : m_arms)
        if (!a.empty()) d = std::max(d, a.back().t);
    return d;
}

void Trajectory::sampleInto(double t, bool loop, DeviceState& out) const {
    const double dur = duration();
    if (loop && dur > 0) t = std::fmod(std::max(t, 0.0), dur);
    out.pedals = 0;
    for (int a = 0; a < kMaxArms; ++a) {
        const auto& s = m_arms[a];
        if (s.empty()) continue;
        ArmState& st = out.arms[a];
        auto it = std::upper_bound(s.begin(), s.end(), t, [](double x, const TrajectorySample& p) { return x < p.t; });
        if (it == s.begin() || it == s.end()) {
            const TrajectorySample& p = it == s.begin() ? s.front() : s.back();
            st.measured_cp = p.pose;
            st.measured_cv = Twist{};
            st.jaw_measured_js = p.grip;
            st.buttons = p.buttons;
            out.pedals |= p.pedals;
            continue;
        }
        const TrajectorySample& p0 = *(it - 1);
        const TrajectorySample& p1 = *it;
        const double h = p1.t - p0.t;
        const double u = std::clamp((t - p0.t) / h, 0.0, 1.0);
        st.measured_cp.position = (1 - u) * p0.pose.position + u * p1.pose.position;
        st.measured_cp.orientation = p0.pose.orientation.slerp(u, p1.pose.orientation);
        st.measured_cv.linear = (p1.pose.position - p0.pose.position) / h;
        const Eigen::AngleAxisd d(p1.pose.orientation * p0.pose.orientation.conjugate());
        st.measured_cv.angular = d.axis() * (d.angle() > M_PI ? d.angle() - 2 * M_PI : d.angle()) / h;
        st.jaw_measured_js = (1 - u) * p0.grip + u * p1.grip;
        st.buttons = p0.buttons;
        out.pedals |= p0.pedals;
    }
}

} // namespace viscera::haptics
