#include "sim/dissection/heat_grid.hpp"

#include "sim/util/format.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace viscera::sim {
namespace {

constexpr double kAbsoluteZero = -273.15;

} // namespace

std::string validate(const HeatGridSettings& s) {
    if (s.nodes < 4 || s.nodes > 256) return "nodes is " + std::to_string(s.nodes) + " (must be 4..256)";
    if (!std::isfinite(s.spacing) || !(s.spacing > 0))
        return "spacing is " + formatNumber(s.spacing) + " (must be > 0)";
    if (!std::isfinite(s.diffusivity) || !(s.diffusivity > 0))
        return "diffusivity is " + formatNumber(s.diffusivity) + " (must be > 0)";
    if (!std::isfinite(s.bodyTemperature) || s.bodyTemperature < kAbsoluteZero)
        return "bodyTemperature is " + formatNumber(s.bodyTemperature) + " (must be finite and >= -273.15)";
    return {};
}

HeatGrid::HeatGrid(const HeatGridSettings& settings) : m_settings(settings), m_n(settings.nodes) {
    if (auto why = validate(settings); !why.empty()) throw std::invalid_argument("sim::HeatGrid: " + why);
    const size_t n3 = size_t(m_n) * m_n * m_n;
    m_u.assign(n3, settings.bodyTemperature);
    m_next.assign(n3, settings.bodyTemperature);
    m_fixed.assign(n3, 0);
}

void HeatGrid::reset() {
    std::fill(m_u.begin(), m_u.end(), m_settings.bodyTemperature);
    m_placed = false;
    m_hasSource = false;
}

Vec3 HeatGrid::origin() const {
    const double dl = m_settings.spacing;
    return Vec3(double(m_originIndex[0]) * dl, double(m_originIndex[1]) * dl, double(m_originIndex[2]) * dl);
}

int HeatGrid::substepsFor(double dt) const {
    if (!(dt > 0)) return 1;
    const double k = std::ceil(dt / stableSubstep());
    return static_cast<int>(std::clamp(k, 1.0, 1e6));
}

void HeatGrid::place(const Vec3& centre) {
    const double dl = m_settings.spacing;
    std::array<int64_t, 3> o;
    for (int a = 0; a < 3; ++a) {
        // Clamp far-away coordinates so that the index arithmetic cannot overflow.
        const double c = std::clamp(centre[a] / dl, -1e15, 1e15);
        o[a] = static_cast<int64_t>(std::llround(c)) - m_n / 2;
    }
    if (m_placed && o == m_originIndex) return;
    const double body = m_settings.bodyTemperature;
    if (!m_placed) {
        std::fill(m_u.begin(), m_u.end(), body);
    } else {
        const int64_t dx = o[0] - m_originIndex[0], dy = o[1] - m_originIndex[1], dz = o[2] - m_originIndex[2];
        for (int k = 0; k < m_n; ++k)
            for (int j = 0; j < m_n; ++j)
                for (int i = 0; i < m_n; ++i) {
                    const int64_t si = i + dx, sj = j + dy, sk = k + dz;
                    const bool inside = si >= 0 && si < m_n && sj >= 0 && sj < m_n && sk >= 0 && sk < m_n;
                    m_next[id(i, j, k)] = inside ? m_u[id(int(si), int(sj), int(sk))] : body;
                }
        m_u.swap(m_next);
    }
    m_originIndex = o;
    m_placed = true;
}

int HeatGrid::advance(const HeatSource& src, double dt) {
    if (!src.centre.allFinite() || !std::isfinite(src.radius) || !std::isfinite(src.temperature) || !std::isfinite(dt))
        throw std::invalid_argument("sim::HeatGrid::advance(): source or dt is not finite");
    if (!(src.radius > 0))
        throw std::invalid_argument("sim::HeatGrid::advance(): radius is " + formatNumber(src.radius) +
                                    " (must be > 0)");
    if (dt < 0) throw std::invalid_argument("sim::HeatGrid::advance(): dt is " + formatNumber(dt) + " (must be >= 0)");
    if (src.temperature < kAbsoluteZero)
        throw std::invalid_argument("sim::HeatGrid::advance(): temperature is " + formatNumber(src.temperature) +
                                    " (must be >= -273.15)");
    place(src.centre);
    m_source = src;
    m_hasSource = true;
    return run(dt, &src);
}

int HeatGrid::advanceUnheated(const Vec3& centre, double dt) {
    if (!centre.allFinite() || !std::isfinite(dt) || dt < 0)
        throw std::invalid_argument("sim::HeatGrid::advanceUnheated(): centre or dt is not finite or dt < 0");
    place(centre);
    m_hasSource = false;
    return run(dt, nullptr);
}

int HeatGrid::run(double dt, const HeatSource* src) {
    const double dl = m_settings.spacing, body = m_settings.bodyTemperature;
    const Vec3 o = origin();
    // Dirichlet nodes: the outer layer at body temperature, the sphere at the tool temperature.
    int nearest[3] = {-1, -1, -1};
    if (src)
        for (int a = 0; a < 3; ++a)
            nearest[a] = std::clamp(int(std::lround((src->centre[a] - o[a]) / dl)), 0, m_n - 1);
    const double r2 = src ? src->radius * src->radius : 0;
    for (int k = 0; k < m_n; ++k)
        for (int j = 0; j < m_n; ++j)
            for (int i = 0; i < m_n; ++i) {
                const size_t n = id(i, j, k);
                bool hot = false;
                if (src) {
                    const Vec3 x = o + dl * Vec3(i, j, k);
                    hot = (x - src->centre).squaredNorm() <= r2 ||
                          (i == nearest[0] && j == nearest[1] && k == nearest[2]);
                }
                const bool edge = i == 0 || j == 0 || k == 0 || i == m_n - 1 || j == m_n - 1 || k == m_n - 1;
                m_fixed[n] = hot ? 2 : (edge ? 1 : 0);
                if (hot)
                    m_u[n] = src->temperature;
                else if (edge)
                    m_u[n] = body;
            }
    if (!(dt > 0)) return 0;
    const int steps = substepsFor(dt);
    const double r = m_settings.diffusivity * (dt / steps) / (dl * dl); // ≤ 1/6
    const size_t sx = 1, sy = size_t(m_n), sz = size_t(m_n) * m_n;
    for (int s = 0; s < steps; ++s) {
        for (int k = 0; k < m_n; ++k)
            for (int j = 0; j < m_n; ++j)
                for (int i = 0; i < m_n; ++i) {
                    const size_t n = id(i, j, k);
                    if (m_fixed[n]) {
                        m_next[n] = m_u[n];
                        continue;
                    }
                    const double u = m_u[n];
                    const double lap = (m_u[n + sx] + m_u[n - sx]) + (m_u[n + sy] + m_u[n - sy]) +
                                       (m_u[n + sz] + m_u[n - sz]) - 6.0 * u;
                    m_next[n] = u + r * lap;
                }
        m_u.swap(m_next);
    }
    return steps;
}

double HeatGrid::temperatureAt(const Vec3& x) const {
    const double body = m_settings.bodyTemperature;
    if (!m_placed || !x.allFinite()) return body;
    if (m_hasSource && (x - m_source.centre).squaredNorm() <= m_source.radius * m_source.radius)
        return m_source.temperature;
    const Vec3 g = (x - origin()) / m_settings.spacing;
    if (!(g.minCoeff() >= 0) || !(g.maxCoeff() <= m_n - 1)) return body;
    int c[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        c[a] = std::min(int(g[a]), m_n - 2);
        f[a] = g[a] - c[a];
    }
    double v = 0;
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
                v += w * m_u[id(c[0] + dx, c[1] + dy, c[2] + dz)];
            }
    return v;
}

double HeatGrid::minTemperature() const {
    return *std::min_element(m_u.begin(), m_u.end());
}

double HeatGrid::maxTemperature() const {
    return *std::max_element(m_u.begin(), m_u.end());
}

} // namespace viscera::sim
