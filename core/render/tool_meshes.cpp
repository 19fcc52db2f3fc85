#include "render/tool_meshes.hpp"

#include "sim/scene/world.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::render {
namespace {

using Vec3 = Eigen::Vector3d;

/// Appends primitives to a vertex list, and to an index list when one is given: the same calls
/// in the same order always give the same counts, so a frame only rewrites positions.
class Builder {
public:
    Builder(std::vector<float>& pos, std::vector<uint32_t>* idx) : m_pos(pos), m_idx(idx) {
        m_pos.clear();
        if (m_idx) m_idx->clear();
    }
    /// A tube through `pts` (≥ 2), `sides` around, frames carried along the polyline (no twist).
    void tube(const Vec3* pts, size_t n, double radius, int sides = 8) {
        Vec3 t = (pts[1] - pts[0]);
        t = t.norm() > 0 ? Vec3(t.normalized()) : Vec3::UnitZ();
        Vec3 u = t.unitOrthogonal();
        const uint32_t first = vertexCount();
        for (size_t i = 0; i < n; ++i) {
            Vec3 ti = i + 1 < n ? Vec3(pts[i + 1] - pts[i]) : Vec3(pts[i] - pts[i - 1]);
            if (ti.norm() > 1e-12) {
                ti.normalize();
                u = (u - u.dot(ti) * ti);
                u = u.norm() > 1e-9 ? Vec3(u.normalized()) : ti.unitOrthogonal();
            }
            const Vec3 v = ti.cross(u);
            for (int s = 0; s < sides; ++s) {
                const double a = 2 * M_PI * s / sides;
                vertex(pts[i] + radius * (std::cos(a) * u + std::sin(a) * v));
            }
        }
        if (!m_idx) return;
        for (size_t i = 0; i + 1 < n; ++i)
            for (int s = 0; s < sides; ++s) {
                const uint32_t a = first + uint32_t(i * sides + s), b = first + uint32_t(i * sides + (s + 1) % sides);
                const uint32_t c = a + uint32_t(sides), d = b + uint32_t(sides);
                tri(a, b, d);
                tri(a, d, c);
            }
        // End caps (fans), so a shaft cut by the view frustum is not hollow.
        for (size_t end : {size_t(0), n - 1}) {
            const uint32_t base = first + uint32_t(end * sides);
            for (int s = 1; s + 1 < sides; ++s)
                end == 0 ? tri(base, base + uint32_t(s + 1), base + uint32_t(s))
                         : tri(base, base + uint32_t(s), base + uint32_t(s + 1));
        }
    }
    void segment(const Vec3& a, const Vec3& b, double radius, int sides = 8) {
        const Vec3 p[2] = {a, b};
        tube(p, 2, radius, sides);
    }
    /// A box from a to b, `halfWidth` along `side` (made ⟂ to b − a) and `halfThickness` across both.
    void plate(const Vec3& a, const Vec3& b, const Vec3& side, double halfWidth, double halfThickness) {
        Vec3 d = b - a;
        d = d.norm() > 0 ? Vec3(d.normalized()) : Vec3::UnitZ();
        Vec3 w = side - side.dot(d) * d;
        w = w.norm() > 1e-9 ? Vec3(w.normalized()) : d.unitOrthogonal();
        const Vec3 t = d.cross(w);
        const uint32_t first = vertexCount();
        for (const Vec3& end : {a, b})
            for (int k = 0; k < 4; ++k) {
                const double sw = (k == 0 || k == 3) ? -1 : 1, st = k < 2 ? -1 : 1;
                vertex(end + sw * halfWidth * w + st * halfThickness * t);
            }
        if (!m_idx) return;
        auto quad = [&](uint32_t p, uint32_t q, uint32_t r, uint32_t s) {
            tri(first + p, first + q, first + r);
            tri(first + p, first + r, first + s);
        };
        quad(0, 3, 2, 1); // end a
        quad(4, 5, 6, 7); // end b
        for (uint32_t k = 0; k < 4; ++k) {
            const uint32_t k1 = (k + 1) % 4;
            quad(k, k1, 4 + k1, 4 + k);
        }
    }
    void sphere(const Vec3& c, double r, int rings = 8, int sides = 12) {
        const uint32_t first = vertexCount();
        for (int i = 0; i <= rings; ++i) {
            const double th = M_PI * i / rings;
            for (int s = 0; s < sides; ++s) {
                const double ph = 2 * M_PI * s / sides;
                vertex(c + r * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
            }
        }
        if (!m_idx) return;
        for (int i = 0; i < rings; ++i)
            for (int s = 0; s < sides; ++s) {
                const uint32_t a = first + uint32_t(i * sides + s), b = first + uint32_t(i * sides + (s + 1) % sides);
                tri(a, a + uint32_t(sides), b + uint32_t(sides));
                tri(a, b + uint32_t(sides), b);
            }
    }

private:
    uint32_t vertexCount() const { return static_cast<uint32_t>(m_pos.size() / 3); }
    void vertex(const Vec3& p) {
        for (int k = 0; k < 3; ++k)
            m_pos.push_back(static_cast<float>(p[k]));
    }
    void tri(uint32_t a, uint32_t b, uint32_t c) { m_idx->insert(m_idx->end(), {a, b, c}); }
    std::vector<float>& m_pos;
    std::vector<uint32_t>* m_idx;
};

constexpr double kBeyondPort = 0.03; ///< m of shaft drawn outside a port

/// A stable axis ⟂ to the shaft: the jaws open in the plane of the shaft and this axis.
Vec3 openingAxis(const Vec3& d) {
    Vec3 u = d.cross(Vec3::UnitZ());
    if (u.norm() < 1e-3) u = d.cross(Vec3::UnitX());
    return u.normalized();
}

void buildInstrument(Builder& b, const ToolPoses::Instrument& in) {
    const Vec3 d = in.direction.norm() > 0 ? Vec3(in.direction.normalized()) : Vec3(-Vec3::UnitZ());
    const Vec3 u = openingAxis(d), side = d.cross(u);
    const double r = std::max(in.radius, 5e-4), L = in.jawLength;
    const double shaftR = 1.6 * r;
    const Vec3 hinge = in.tip - L * d;
    const double shaft = std::clamp(in.shaftLength, 0.01, 1.0);
    if (in.kind == "energy_hook") {
        b.segment(hinge - shaft * d, hinge, shaftR, 12);
        b.segment(hinge, in.tip, 0.45 * r, 8);                               // insulated rod
        b.segment(in.tip - 0.15 * L * u, in.tip + 0.35 * L * u, 0.4 * r, 8); // the hook, across the shaft
        return;
    }
    // Grasper and clip applier: two jaws hinged at the clevis, opened in the (d, u) plane.
    const bool clip = in.kind == "clip_applier";
    const double half = (clip ? 12.0 : 28.0) * M_PI / 180.0 * std::clamp(in.jaw, 0.0, 1.0);
    b.segment(hinge - shaft * d, hinge, shaftR, 12);
    for (int k : {-1, 1}) {
        const Vec3 dir = std::cos(half) * d + k * std::sin(half) * u;
        const Vec3 base = hinge + k * 0.35 * r * u;
        b.plate(base, base + L * dir, side, clip ? 0.8 * r : r, 0.35 * r);
    }
}

TissueMaterial toolMaterial(const char* name, const Eigen::Vector3f& colour, float roughness, float metallic) {
    TissueMaterial m;
    m.name = name;
    m.surface = {colour, 1.0f, 0.0f};
    m.granular.weight = 0.0f;
    m.connective.weight = 0.0f;
    m.submucosa.weight = 0.0f;
    m.roughness = roughness;
    m.granularRoughness = 0.0f;
    m.metallic = metallic;
    m.reflection = 0.0f;
    m.f0 = 0.04f;
    m.sssWeight = 0.0f;
    m.flags = kFlagTool;
    return m;
}

/// `path` resampled to n points by arc length (the unused tail gathered at its end); false when
/// the path is shorter than 0.1 mm (nothing to draw).
bool resample(const std::vector<Vec3>& path, size_t n, std::vector<Vec3>& out) {
    out.assign(n, path.empty() ? Vec3::Zero() : path.back());
    if (path.size() < 2) return false;
    std::vector<double> s(path.size(), 0.0);
    for (size_t i = 1; i < path.size(); ++i)
        s[i] = s[i - 1] + (path[i] - path[i - 1]).norm();
    if (!(s.back() > 1e-4)) return false;
    size_t j = 0;
    for (size_t k = 0; k < n; ++k) {
        const double at = s.back() * double(k) / double(n - 1);
        while (j + 2 < path.size() && s[j + 1] < at)
            ++j;
        const double len = s[j + 1] - s[j], f = len > 0 ? std::clamp((at - s[j]) / len, 0.0, 1.0) : 0.0;
        out[k] = path[j] + f * (path[j + 1] - path[j]);
    }
    return true;
}

} // namespace

ToolPoses toolPoses(const sim::World& world) {
    ToolPoses p;
    if (const sim::InteractionRuntime* in = world.interaction()) {
        const auto& now = in->summary().instruments;
        for (size_t i = 0; i < in->instrumentCount(); ++i) {
            const sim::InstrumentDesc& d = in->instrumentDesc(i);
            ToolPoses::Instrument t;
            t.name = d.name;
            t.kind = sim::kindName(d.kind);
            t.radius = d.radius;
            t.jawLength = d.jawLength;
            if (i < now.size()) {
                t.tip = now[i].tip;
                t.direction = now[i].direction;
                t.jaw = now[i].jaw;
                t.act = now[i].act;
                t.grasped = now[i].grasped;
            } else { // before the first frame: where the track starts
                const sim::InstrumentKey k = in->restKey(i);
                t.tip = k.position;
                t.direction = k.direction;
                t.jaw = k.jaw;
            }
            if (d.port.declared) t.shaftLength = (t.tip - d.port.position).norm() + kBeyondPort - t.jawLength;
            if (d.kind == sim::InstrumentDesc::Kind::ClipApplier) ++p.maxClips;
            p.instruments.push_back(std::move(t));
        }
        for (const sim::ClipState& c : in->summary().clips)
            p.clips.push_back(c.legs);
    }
    for (size_t t = 0; t < world.toolCount(); ++t) {
        const sim::ToolContact& c = world.toolContact(t);
        const sim::ToolDesc& d = world.toolDesc(t);
        p.probes.push_back({c.centre, d.radius, d.port.declared, d.port.position});
    }
    if (const sim::Laparoscope* scope = world.laparoscope()) {
        const sim::ScopePose& s = scope->pose();
        p.scope = {true, s.tip, s.view, s.up, scope->desc().fovDeg, scope->steering()};
    }
    if (const sim::SutureReport* s = world.sutureReport()) {
        const sim::NeedleCurve curve = s->needleCurve();
        const double len = s->needleLength();
        for (int k = 0; k <= 24; ++k)
            p.needle.push_back(curve.point(len * k / 24.0));
        p.instruments.push_back(needleHolderPose(p.needle));
        p.thread = s->threadPath();
        if (p.thread.size() < 2) // not through the tissue yet: a tail behind the needle's end
            p.thread.insert(p.thread.begin(), curve.point(0.0) - 0.012 * curve.tangent(0.0));
    }
    return p;
}

ToolPoses::Instrument needleHolderPose(const std::vector<Eigen::Vector3d>& points) {
    ToolPoses::Instrument h;
    h.name = "needle holder";
    h.kind = "needle_holder";
    h.jaw = 0;           // closed on the needle
    h.jawLength = 0.005; // a fine holder, to the scale of the needle (0.3 mm wire)
    h.radius = 0.0008;
    if (points.size() < 2) return h;
    const size_t k = std::min(points.size() - 1, std::max<size_t>(1, points.size() / 3));
    h.tip = points[k];
    Vec3 tangent = points[std::min(k + 1, points.size() - 1)] - points[k - 1];
    if (tangent.norm() < 1e-12) tangent = Vec3::UnitX();
    tangent.normalize();
    // The arc's plane, from its ends and its middle.
    const Vec3 chord = points.back() - points.front();
    const Vec3 bow = points[points.size() / 2] - 0.5 * (points.front() + points.back());
    Vec3 normal = chord.cross(bow);
    if (normal.norm() < 1e-12) normal = tangent.unitOrthogonal();
    normal.normalize();
    // In the plane, across the needle; the arc's middle bows away from its centre.
    Vec3 outward = normal.cross(tangent);
    if (outward.dot(bow) < 0) outward = -outward;
    // Shaft along −direction: away from the centre and out of the plane.
    h.direction = -(0.7 * outward + 0.7 * normal).normalized();
    return h;
}

template <class B>
bool ToolMeshes::build(B& b, const Part& part, const ToolPoses& poses, RenderMesh& m, std::vector<Vec3>& pts) const {
    switch (part.kind) {
    case Part::Kind::Instrument: {
        if (part.index >= poses.instruments.size()) return false;
        const ToolPoses::Instrument& in = poses.instruments[part.index];
        buildInstrument(b, in);
        m.material = in.kind == "energy_hook" && in.act ? m_active : m_steel;
        return true;
    }
    case Part::Kind::Probe: {
        if (part.index >= poses.probes.size()) return false;
        const ToolPoses::Probe& pr = poses.probes[part.index];
        b.sphere(pr.centre, pr.radius);
        if (pr.hasPort) { // the shaft from the sphere out through the port
            const Vec3 out = pr.port - pr.centre;
            const Vec3 d = out.norm() > 1e-9 ? Vec3(out.normalized()) : Vec3(Vec3::UnitZ());
            b.segment(pr.centre, pr.port + kBeyondPort * d, 0.3 * pr.radius, 12);
        }
        return true;
    }
    case Part::Kind::Clip: {
        m.visible = part.index < poses.clips.size();
        if (!m.visible) { // not fired yet: hidden, with the fired clip's three plates so the topology is fixed
            for (int k = 0; k < 3; ++k)
                b.plate(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1e-4, 1e-4);
            return true;
        }
        const auto& q = poses.clips[part.index];
        const Vec3 across = q[2] - q[0];
        b.plate(q[0], q[1], across.cross(q[1] - q[0]), 3.5e-4, 2.0e-4);
        b.plate(q[2], q[3], across.cross(q[3] - q[2]), 3.5e-4, 2.0e-4);
        b.plate(q[1], q[3], q[1] - q[0], 2.0e-4, 2.0e-4); // the hinge joining the legs
        return true;
    }
    case Part::Kind::Needle:
        if (poses.needle.size() < 2) return false;
        b.tube(poses.needle.data(), poses.needle.size(), 3.0e-4, 8);
        return true;
    case Part::Kind::Thread:
        m.visible = resample(poses.thread, kThreadPoints, pts);
        b.tube(pts.data(), pts.size(), 2.4e-4, 6);
        return true;
    }
    return false;
}

ToolMeshes::ToolMeshes(SceneView& view, const ToolPoses& first) {
    if (first.empty()) return;
    m_steel = view.addMaterial(toolMaterial("instrument steel", {0.78f, 0.79f, 0.81f}, 0.32f, 0.55f));
    m_active = view.addMaterial(toolMaterial("instrument energized", {0.98f, 0.50f, 0.14f}, 0.45f, 0.3f));
    m_clip = view.addMaterial(toolMaterial("titanium clip", {0.74f, 0.71f, 0.64f}, 0.32f, 0.85f));
    m_thread = view.addMaterial(toolMaterial("suture thread", {0.32f, 0.12f, 0.48f}, 0.6f, 0.0f));
    m_probe = view.addMaterial(toolMaterial("probe", {0.22f, 0.42f, 0.85f}, 0.35f, 0.1f));
    auto add = [&](const std::string& name, Part::Kind kind, size_t index, uint32_t material) {
        RenderMesh m;
        m.name = name;
        m.material = material;
        view.meshes().push_back(std::move(m));
        m_meshes.push_back({kind, index, view.meshes().size() - 1});
    };
    for (size_t i = 0; i < first.instruments.size(); ++i)
        add(first.instruments[i].name, Part::Kind::Instrument, i, m_steel);
    for (size_t i = 0; i < first.probes.size(); ++i)
        add("probe " + std::to_string(i), Part::Kind::Probe, i, m_probe);
    for (size_t i = 0; i < first.maxClips; ++i)
        add("clip " + std::to_string(i), Part::Kind::Clip, i, m_clip);
    if (!first.needle.empty()) {
        add("needle", Part::Kind::Needle, 0, m_steel);
        add("thread", Part::Kind::Thread, 0, m_thread);
    }
    // Topology from the first snapshot; update() rewrites the same vertices in the same order.
    std::vector<Vec3> pts;
    for (const Part& part : m_meshes) {
        RenderMesh& m = view.meshes()[part.mesh];
        Builder b(m.positions, &m.indices);
        build(b, part, first, m, pts);
        const size_t nv = m.positions.size() / 3;
        m.rest = m.positions;
        m.normals.assign(m.positions.size(), 0.0f);
        m.thickness.assign(nv, kThicknessMapRange);
        m.sampleMap.assign(nv, 0.0f);
        m.heat.assign(nv, 0.0f);
        view.recomputeNormals(part.mesh);
    }
}

void ToolMeshes::update(SceneView& view, const ToolPoses& poses) {
    std::vector<Vec3> pts;
    for (const Part& part : m_meshes) {
        if (part.mesh >= view.meshes().size()) continue;
        RenderMesh& m = view.meshes()[part.mesh];
        const size_t before = m.positions.size();
        Builder b(m_scratch, nullptr);
        if (!build(b, part, poses, m, pts) || !m.visible) continue;
        if (m_scratch.size() != before) continue; // another topology: keep the last pose
        bool finite = true;
        for (float v : m_scratch)
            finite = finite && std::isfinite(v);
        if (!finite) continue;
        std::copy(m_scratch.begin(), m_scratch.end(), m.positions.begin());
        view.recomputeNormals(part.mesh);
    }
}

} // namespace viscera::render
