#include "sim/scene/tool_probe.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::sim {

std::vector<double> lumpedMasses(const TetMesh& mesh, double density, const std::vector<int32_t>& fixedNodes) {
    std::vector<double> m(mesh.vertexCount(), 0.0);
    const auto& x = mesh.positions();
    for (const auto& t : mesh.tets()) {
        const double vol = std::abs((x[t[1]] - x[t[0]]).dot((x[t[2]] - x[t[0]]).cross(x[t[3]] - x[t[0]]))) / 6.0;
        for (int k = 0; k < 4; ++k)
            m[t[k]] += density * vol / 4.0;
    }
    for (int32_t f : fixedNodes)
        if (f >= 0 && static_cast<size_t>(f) < m.size()) m[f] = 0;
    return m;
}

ToolProbes::ToolProbes(std::vector<ToolDesc> tools, std::vector<Body> bodies, double dt)
    : m_tools(std::move(tools)), m_bodies(std::move(bodies)), m_dt(dt) {
    m_contacts.resize(m_tools.size());
    for (const auto& t : m_tools) {
        m_pos.push_back(t.start);
        m_portFrames.push_back(makePortFrame(t.port, t.start, t.motionScale)); // used where declared
    }
    m_stepStart = m_pos;
    for (size_t t = 0; t < m_tools.size(); ++t)
        m_contacts[t].centre = m_pos[t];
}

void ToolProbes::setPosition(size_t t, const Vec3& centre) {
    if (t >= m_pos.size() || !centre.allFinite()) return;
    Vec3 d = centre - m_pos[t];
    const double r = m_tools[t].radius, n = d.norm();
    if (n > r) d *= r / n;
    m_pos[t] += d;
    // A probe through a port: its shaft from the port to the centre, within the port's limits.
    if (m_tools[t].port.declared) m_pos[t] = constrainToPort(m_portFrames[t], m_pos[t]).tip;
}

std::vector<char> ToolProbes::apply(std::vector<std::vector<Vec3>>& x, std::vector<std::vector<Vec3>>& v,
                                    bool measure) {
    std::vector<char> changed(x.size(), 0);
    for (size_t t = 0; t < m_tools.size(); ++t) {
        const Vec3 c = m_pos[t];
        const double r = m_tools[t].radius;
        const Vec3 toolVel = measure ? Vec3::Zero() : Vec3((c - m_stepStart[t]) / m_dt);
        ToolContact out;
        out.centre = c;
        double depth = 0, nearest = 1e18, modulus = 0;
        Vec3 dir = Vec3::Zero(), nearestDir = Vec3::UnitZ();
        for (size_t b = 0; b < x.size() && b < m_bodies.size(); ++b) {
            const auto& mass = m_bodies[b].mass;
            for (size_t i = 0; i < x[b].size(); ++i) {
                if (mass[i] <= 0) continue;
                Vec3 d = x[b][i] - c;
                const double dist = d.norm();
                if (dist >= r) {
                    if (dist - r < nearest) {
                        nearest = dist - r;
                        nearestDir = -d / dist;
                    }
                    continue;
                }
                const Vec3 n = dist > 1e-12 ? Vec3(d / dist) : Vec3::UnitZ();
                const double pen = r - dist;
                if (pen > depth) {
                    depth = pen;
                    modulus = m_bodies[b].modulus;
                }
                dir -= mass[i] * pen * n; // the tissue pushes the probe away from the node
                ++out.nodes;
                x[b][i] = c + r * n;
                const double vn = (v[b][i] - toolVel).dot(n);
                if (vn < 0) v[b][i] -= vn * n;
                changed[b] = 1;
            }
        }
        if (!measure) {
            m_stepStart[t] = c;
            continue;
        }
        const ToolDesc& td = m_tools[t];
        if (modulus <= 0)
            for (const auto& body : m_bodies)
                modulus = std::max(modulus, body.modulus);
        if (out.nodes > 0 && dir.norm() > 0) {
            out.normal = dir.normalized();
            out.penetration = depth;
            out.gap = 0;
            double f, k;
            if (td.stiffness > 0) {
                f = td.stiffness * depth;
                k = td.stiffness;
            } else {
                f = 4.0 / 3.0 * modulus * std::sqrt(r) * std::pow(depth, 1.5);
                k = 2.0 * modulus * std::sqrt(r * std::max(depth, r / 8));
            }
            out.force = f * out.normal;
            out.stiffness = k;
        } else {
            out.normal = nearestDir;
            out.gap = nearest;
            out.stiffness = td.stiffness > 0 ? td.stiffness : 2.0 * modulus * std::sqrt(r * r / 8);
        }
        m_contacts[t] = out;
    }
    return changed;
}

} // namespace viscera::sim
