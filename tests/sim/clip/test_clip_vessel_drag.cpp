// Acceptance [A §5.4]: "A clip stays within 0.5 mm of the vessel surface while the vessel is
// dragged 3 cm." A hollow vessel (radius 2–3 mm, 6 cm, stable Neo-Hookean E = 5 kPa, ν = 0.45,
// 1050 kg/m³, gravity) hangs from its top ring in XPBD. After 1 s of settling a clip is applied
// across the middle; then the top ring (the fixed nodes) is dragged 3 cm over 1.5 s (smooth
// step) and held for 0.5 s: straight up along the vessel, or sideways (the vessel swings and
// bends). Every frame the clip follows by [A eq. 5.15–5.18]; the distance from each contact point
// (inner-jaw points that touched the vessel at application, moved with the clip) to the
// deformed vessel surface (closest point on the boundary triangles) must stay ≤ 0.5 mm.
// In the sideways run the bottom ring is held too, so the vessel bends and stretches.
#include "sim/clip/clip_flattening.hpp"
#include "sim/collision/distance.hpp"
#include "sim/diagnostics/stability_check.hpp"
#include "sim/material/stable_neo_hookean.hpp"
#include "sim/util/format.hpp"
#include "sim/xpbd/xpbd_system.hpp"

#include "clip_test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace viscera::sim;
using namespace viscera::sim::testing;

namespace {

constexpr int kSlices = 16, kRings = 16;
constexpr double kLength = 0.06;

int32_t node(int ring, int layer, int slice) {
    return (ring * 2 + layer) * kSlices + slice;
}

Vec3 ringCentre(const std::vector<Vec3>& x, int ring) {
    Vec3 c = Vec3::Zero();
    for (int l = 0; l < 2; ++l)
        for (int i = 0; i < kSlices; ++i)
            c += x[node(ring, l, i)];
    return c / (2 * kSlices);
}

struct DragResult {
    double maxDistance = 0, meanDistance = 0, maxAtApplication = 0;
    size_t contacts = 0;
    bool finite = true;
    int frames = 0, fallbacks = 0, rejected = 0;
    double maxFlattenShift = 0;
    double maxRotation = 0;    ///< largest clip rotation from the application pose, rad
    double clipTravel = 0;     ///< largest contact point displacement from application to the end, m
    std::vector<double> trace; ///< per-frame max distance
    std::vector<Vec3> finalContacts;
};

DragResult runDrag(const Vec3& drag, bool holdBottom, bool flatten) {
    HollowTubeSpec spec;
    spec.start = Vec3::Zero();
    spec.end = Vec3(0, 0, -kLength);
    spec.innerRadius = 0.002;
    spec.outerRadius = 0.003;
    spec.slices = kSlices;
    spec.layers = 1;
    spec.rings = kRings;
    auto mesh = makeHollowTubeTetMesh(spec);
    mesh->requireLevel(3);
    const double E = 5000, nu = 0.45;
    TetBodyDesc body;
    body.name = "vessel";
    body.mesh = mesh.get();
    body.model = std::make_shared<StableNeoHookeanModel>(E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu)));
    body.density = 1050;
    for (int l = 0; l < 2; ++l)
        for (int i = 0; i < kSlices; ++i)
            body.fixedNodes.push_back(node(0, l, i));
    const size_t dragged = body.fixedNodes.size(); // the top ring moves, the bottom one (if held) not
    if (holdBottom)
        for (int l = 0; l < 2; ++l)
            for (int i = 0; i < kSlices; ++i)
                body.fixedNodes.push_back(node(kRings, l, i));
    XpbdSystemDesc desc;
    desc.tetBodies.push_back(body);
    XpbdSettings settings;
    settings.threads = 1;
    // As many substeps as the load-time stability check asks for (145 for this 1 mm wall).
    settings.substeps = std::max(10, assessStability(*mesh, *body.model, body.density, {}, settings).requiredSubsteps);
    auto sys = XpbdSystem::create(desc, settings);

    for (int f = 0; f < 60; ++f)
        sys->step(); // settle under gravity

    // Clip across the middle ring, jaws closing along y, inner faces touching the outer wall.
    const auto& x0 = sys->tetPositions(0);
    const Vec3 centre = ringCentre(x0, kRings / 2);
    const Vec3 axis = ringCentre(x0, kRings / 2 - 1) - ringCentre(x0, kRings / 2 + 1);
    const Vec3 n = (Vec3::UnitY() - Vec3::UnitY().dot(axis.normalized()) * axis.normalized()).normalized();
    double gap = 0;
    for (int i = 0; i < kSlices; ++i)
        gap = std::max(gap, std::abs((x0[node(kRings / 2, 1, i)] - centre).dot(n)));
    ClipDesc clip = clipAcross(centre, axis, n, gap, 0.004, 0.001, 33);

    const TriMesh& bnd = mesh->boundary();
    const auto& bmap = mesh->boundaryVertexMap();
    auto surfacePoint = [&](const std::vector<Vec3>& x, int t) {
        const Tri& tr = bnd.triangles()[t];
        return std::array<Vec3, 3>{x[bmap[tr[0]]], x[bmap[tr[1]]], x[bmap[tr[2]]]};
    };
    // Boundary triangles near the clip (any vertex within 1 cm at application): the surface the
    // contact points can be closest to. Distances are exact closest points on these triangles.
    std::vector<int> nearTris;
    for (int t = 0; t < static_cast<int>(bnd.triangleCount()); ++t)
        for (const Vec3& p : surfacePoint(x0, t))
            if ((p - centre).norm() < 0.01) {
                nearTris.push_back(t);
                break;
            }
    auto distance = [&](const std::vector<Vec3>& x, const Vec3& p) {
        double best = std::numeric_limits<double>::infinity();
        for (int t : nearTris) {
            const auto v = surfacePoint(x, t);
            best = std::min(best, (closestPointOnTriangle(p, v[0], v[1], v[2]).point - p).norm());
        }
        return best;
    };
    // Contact points: inner-face samples within 0.05 mm of the vessel at application.
    std::vector<Vec3> touching;
    for (const Vec3& p : clip.contactPoints)
        if (distance(x0, p) <= 0.05e-3) touching.push_back(p);
    clip.contactPoints = touching;

    DragResult r;
    auto att = ClipAttachment::apply(*mesh, x0, clip);
    r.contacts = touching.size();
    for (const Vec3& p : att->contactPoints())
        r.maxAtApplication = std::max(r.maxAtApplication, distance(x0, p));

    // Render mesh = the boundary vertices; skeleton = the ring centres at application.
    std::vector<Vec3> skeleton;
    for (int k = 0; k <= kRings; ++k)
        skeleton.push_back(ringCentre(x0, k));
    auto renderOf = [&](const std::vector<Vec3>& x) {
        std::vector<Vec3> v(bmap.size());
        for (size_t i = 0; i < bmap.size(); ++i)
            v[i] = x[bmap[i]];
        return v;
    };
    std::unique_ptr<ClipFlattening> fl;
    FlattenSettings fs;
    if (flatten) fl = ClipFlattening::create(*att, renderOf(x0), skeleton, fs);

    std::vector<Vec3> fixed0;
    for (int32_t v : body.fixedNodes)
        fixed0.push_back(x0[v]);
    const int dragFrames = 90, holdFrames = 30;
    const double dt = settings.dt;
    double sum = 0;
    size_t count = 0;
    std::vector<Vec3> flat;
    for (int f = 1; f <= dragFrames + holdFrames; ++f) {
        const double u = std::min(1.0, double(f) / dragFrames);
        const double s = u * u * (3 - 2 * u), ds = f <= dragFrames ? 6 * u * (1 - u) / (dragFrames * dt) : 0;
        std::vector<Vec3> x = sys->tetPositions(0), v = sys->tetVelocities(0);
        for (size_t k = 0; k < dragged; ++k) {
            x[body.fixedNodes[k]] = fixed0[k] + s * drag;
            v[body.fixedNodes[k]] = ds * drag;
        }
        sys->setTetState(0, x, v);
        const StepStats st = sys->step();
        const auto& xs = sys->tetPositions(0);
        r.finite = r.finite && st.finite;
        for (const Vec3& p : xs)
            r.finite = r.finite && p.allFinite();
        if (att->update(xs) != ClipUpdateStatus::Ok) ++r.rejected;
        r.maxRotation = std::max(r.maxRotation, rotationAngleBetween(att->relativeRotation(), Mat3::Identity()));
        double frameMax = 0;
        for (const Vec3& p : att->contactPoints()) {
            r.finite = r.finite && p.allFinite();
            const double d = distance(xs, p);
            frameMax = std::max(frameMax, d);
            sum += d;
            ++count;
        }
        for (const Vec3& p : att->vertices())
            r.finite = r.finite && p.allFinite();
        r.trace.push_back(frameMax);
        r.maxDistance = std::max(r.maxDistance, frameMax);
        if (fl) {
            const auto render = renderOf(xs);
            fl->flattenInto(*att, render, flat);
            for (size_t i = 0; i < flat.size(); ++i) {
                r.finite = r.finite && flat[i].allFinite();
                r.maxFlattenShift = std::max(r.maxFlattenShift, (flat[i] - render[i]).norm());
            }
        }
        ++r.frames;
    }
    r.meanDistance = sum / static_cast<double>(count);
    r.fallbacks = att->fallbackCount();
    r.finalContacts = att->contactPoints();
    for (size_t i = 0; i < r.finalContacts.size(); ++i)
        r.clipTravel = std::max(r.clipTravel, (r.finalContacts[i] - att->applicationContactPoints()[i]).norm());
    return r;
}

void check(const std::string& name, const Vec3& drag, bool holdBottom, double minRotation) {
    const DragResult a = runDrag(drag, holdBottom, true);
    ::testing::Test::RecordProperty(name + "_max_mm", formatNumber(a.maxDistance * 1e3, 4));
    ::testing::Test::RecordProperty(name + "_mean_mm", formatNumber(a.meanDistance * 1e3, 4));
    ::testing::Test::RecordProperty(name + "_contacts", std::to_string(a.contacts));
    ::testing::Test::RecordProperty(name + "_max_flatten_shift_mm", formatNumber(a.maxFlattenShift * 1e3, 4));
    ::testing::Test::RecordProperty(name + "_max_clip_rotation_deg",
                                    formatNumber(a.maxRotation * 180 / 3.141592653589793, 4));
    EXPECT_GE(a.maxRotation, minRotation);
    EXPECT_TRUE(a.finite);
    EXPECT_EQ(a.rejected, 0);
    EXPECT_EQ(a.frames, 120);
    EXPECT_GE(a.contacts, 20u);
    EXPECT_LE(a.maxAtApplication, 0.05e-3);
    EXPECT_LE(a.maxDistance, 0.5e-3) << name << ": max " << a.maxDistance * 1e3 << " mm, mean " << a.meanDistance * 1e3
                                     << " mm";
    EXPECT_GT(a.maxFlattenShift, 0.0);
    EXPECT_LE(a.maxFlattenShift, 0.8 * 0.003 + 1e-4); // κ × (a bit more than) the outer radius
    // The clip really travelled with the vessel (the check is not vacuous).
    EXPECT_GT(a.clipTravel, 0.015);
    ::testing::Test::RecordProperty(name + "_clip_travel_mm", formatNumber(a.clipTravel * 1e3, 4));
    // Repeat run, without flattening: bit-identical figures (flattening never touches physics).
    const DragResult b = runDrag(drag, holdBottom, false);
    EXPECT_EQ(a.trace, b.trace);
    EXPECT_EQ(a.finalContacts, b.finalContacts);
}

} // namespace

TEST(ClipVesselDrag, StraightDragAlongTheVessel) {
    check("straight", Vec3(0, 0, 0.03), false, 0.0);
}

TEST(ClipVesselDrag, SidewaysDragBendsTheVessel) {
    // The bottom ring is held as well, so the top ring dragged sideways bends and stretches the
    // vessel (the chord turns by atan(3/6) = 27°).
    check("sideways", Vec3(0.03, 0, 0), true, 0.2);
}
