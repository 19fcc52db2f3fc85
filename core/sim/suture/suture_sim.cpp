#include "sim/suture/suture_sim.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <stdexcept>

namespace viscera::sim {
namespace {

bool finitePose(const Eigen::Isometry3d& p) {
    return p.matrix().allFinite();
}

/// Orthonormal pair spanning the plane normal to w [B eq. 3.30–3.31].
void normalPlane(const Vec3& w, Vec3& u, Vec3& v) {
    const Vec3 axes[3] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
    for (const Vec3& e : axes) {
        const Vec3 a = w.cross(e);
        if (a.norm() > 0.3) {
            u = a.cross(w).normalized();
            v = w.cross(u);
            return;
        }
    }
    u = Vec3::UnitX();
    v = Vec3::UnitY();
}

} // namespace

ThreadSegmentLinearization linearizeThreadSegment(const Vec3& ra, const Vec3& rb, double eps) {
    ThreadSegmentLinearization l;
    const Vec3 d = rb - ra;
    const double n = d.norm();
    if (!std::isfinite(n) || !(eps > 0)) return l;
    l.length = n >= eps ? n : (n * n / (2 * eps) + eps / 2);
    l.direction = d / std::max(n, eps);
    l.offset = l.length - l.direction.dot(d);
    return l;
}

double NeedleSpec::length_() const {
    return shape == Shape::Semicircle ? std::numbers::pi * radius : length;
}

std::string validate(const SutureSettings& s) {
    if (auto why = validate(s.fem); !why.empty()) return why;
    const NeedleSpec& n = s.needle;
    if (!(n.radius > 0) || !(n.length > 0)) return "needle radius and length must be positive";
    if (!(n.handle >= 0 && n.handle <= n.length_()))
        return "needle handle must lie on the needle (0 <= handle <= length)";
    if (!(n.punctureForce > 0) || !std::isfinite(n.punctureForce)) return "needle puncture_force must be positive";
    if (!(s.thread.length > 0) || !(s.thread.slack >= 0) || !(s.thread.stabilization > 0))
        return "thread length and stabilization must be positive, slack >= 0";
    if (!(s.thread.maxStrainPerStep > 0 && s.thread.maxStrainPerStep < 1))
        return "thread max_strain_per_step must be in (0, 1)";
    if (!(s.contactThickness > 0) || s.contactRounds < 0 || s.contactsPerRound < 1 || s.maxContacts < 1)
        return "contact thickness must be positive, rounds >= 0, per round >= 1, max_contacts >= 1";
    if (s.contactLookaheadSteps < 0 || s.contactLookaheadEvery < 1 || !(s.contactLookaheadDistance >= 0))
        return "contact_lookahead_steps and _distance must be >= 0, contact_lookahead_every >= 1";
    return {};
}

NeedleCurve needleCurve(const NeedleSpec& spec, const Eigen::Isometry3d& pose) {
    const Eigen::Matrix3d R = pose.linear();
    if (spec.shape == NeedleSpec::Shape::Straight) return NeedleCurve::straight(pose.translation(), R.col(0));
    return NeedleCurve::arc(pose.translation(), R.col(0), R.col(1), spec.radius);
}

Eigen::Isometry3d slidePose(const NeedleSpec& spec, const Eigen::Isometry3d& pose, double sigma) {
    Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
    if (spec.shape == NeedleSpec::Shape::Straight)
        local.translation() = Vec3(sigma, 0, 0);
    else
        local.linear() = Eigen::AngleAxisd(sigma / spec.radius, Vec3::UnitZ()).toRotationMatrix();
    return pose * local;
}

double slidingAmount(const NeedleSpec& spec, const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) {
    const NeedleCurve a = needleCurve(spec, from), b = needleCurve(spec, to);
    const Vec3 h0 = a.point(spec.handle), h1 = b.point(spec.handle);
    if (spec.shape == NeedleSpec::Shape::Straight) return (h1 - h0).dot(a.w); // eq. 3.9
    const Vec3 n = a.normal();
    const Vec3 c = h1 - a.p; // eq. 3.12–3.17
    Vec3 q = c - c.dot(n) * n;
    if (!(q.norm() > 1e-12 * spec.radius)) return 0;
    q.normalize();
    const Vec3 ah = (h0 - a.p).normalized(), bh = q;
    return spec.radius * std::atan2(n.dot(ah.cross(bh)), ah.dot(bh)); // signed angle, accurate near 0
}

SutureSimulation::~SutureSimulation() = default;

std::unique_ptr<SutureSimulation> SutureSimulation::create(std::unique_ptr<TetMesh> mesh,
                                                           const std::vector<int32_t>& fixed,
                                                           const SutureSettings& settings,
                                                           const Eigen::Isometry3d& initialPose) {
    if (auto why = validate(settings); !why.empty())
        throw std::invalid_argument("sim::SutureSimulation::create(): " + why);
    if (!mesh) throw std::invalid_argument("sim::SutureSimulation::create(): no mesh");
    if (!finitePose(initialPose))
        throw std::invalid_argument("sim::SutureSimulation::create(): initial needle pose is not finite");
    std::unique_ptr<SutureSimulation> s(new SutureSimulation());
    s->m_s = settings;
    mesh->requireLevel(3);
    s->m_mesh = std::move(mesh);
    s->m_fem = CorotationalFem::create(*s->m_mesh, fixed, settings.fem);
    s->m_tracker = std::make_unique<TipTracker>(*s->m_mesh);
    if (settings.contact) s->m_detector = std::make_unique<ContactDetector>(*s->m_mesh, settings.selfContact);
    s->m_pose = initialPose;
    return s;
}

Vec3 SutureSimulation::materialPoint(int32_t face, const Vec3& xi) const {
    const auto v = m_mesh->halfFacetVertices(face);
    const auto& x = m_fem->positions();
    return xi[0] * x[v[0]] + xi[1] * x[v[1]] + xi[2] * x[v[2]];
}

ConstraintRow SutureSimulation::pointRow(int32_t face, const Vec3& xi, const Vec3& dir, double b) const {
    ConstraintRow r;
    const auto v = m_mesh->halfFacetVertices(face);
    for (int k = 0; k < 3; ++k)
        if (xi[k] != 0) r.terms.push_back({v[k], xi[k] * dir});
    r.b = b;
    return r;
}

int32_t SutureSimulation::topCell() const {
    return m_history.empty() ? kNone : m_history.back().cell;
}

std::vector<Vec3> SutureSimulation::puncturePoints() const {
    std::vector<Vec3> out;
    for (const HistoryEntry& e : m_history)
        if (e.puncture() && e.alpha < 0) out.push_back(materialPoint(e.face, e.xi));
    return out;
}

void SutureSimulation::trackForward(const NeedleCurve& curve, double sigma, bool stopAtBoundary, SutureStepStats& st,
                                    Crossing* boundaryHit) {
    const double l = m_s.needle.length_();
    std::vector<Crossing> cr;
    TrackOptions opt;
    opt.stopAtBoundary = stopAtBoundary;
    opt.maxCrossings = 4096;
    m_tracker->track(m_fem->positions(), curve, l, l + sigma, topCell(), cr, opt);
    for (const Crossing& c : cr) {
        if (stopAtBoundary && c.boundary()) {
            if (boundaryHit) *boundaryHit = c;
            return;
        }
        HistoryEntry e;
        e.face = c.face;
        e.xi = c.xi;
        e.alpha = c.alpha; // parameter of the pre-slide curve; shiftParameters() moves it by −σ
        e.cell = c.toCell;
        e.entersMesh = c.fromCell == kNone;
        e.exitsMesh = c.toCell == kNone;
        if (e.face == kNone) continue;
        if (e.puncture()) {
            ++m_punctures;
            st.punctured = true;
        }
        m_history.push_back(e);
    }
}

void SutureSimulation::shiftParameters(double sigma) {
    const double l = m_s.needle.length_();
    for (HistoryEntry& e : m_history)
        e.alpha -= sigma; // eq. 3.26
    while (!m_history.empty() && m_history.back().alpha > l + 1e-12)
        m_history.pop_back(); // backward sliding
    const double eta = m_s.thread.length;
    m_history.erase(
        std::remove_if(m_history.begin(), m_history.end(), [&](const HistoryEntry& e) { return e.alpha < -eta; }),
        m_history.end());
}

void SutureSimulation::replay(const Eigen::Isometry3d& from, const std::vector<Eigen::Isometry3d>& log,
                              bool allowPuncture, SutureStepStats& st) {
    Eigen::Isometry3d pose = from;
    for (const Eigen::Isometry3d& next : log) {
        const double sigma = slidingAmount(m_s.needle, pose, next);
        if (sigma > 0) {
            Crossing hit;
            hit.face = kNone;
            trackForward(needleCurve(m_s.needle, pose), sigma, !allowPuncture, st, &hit);
        }
        shiftParameters(sigma);
        pose = next;
    }
}

void SutureSimulation::clearNeedleConstraints() {
    for (int id : m_needleIds)
        m_fem->removeConstraint(id);
    m_needleIds.clear();
    m_needleEntryOf.clear();
}

void SutureSimulation::addNeedleConstraints(bool slip) {
    clearNeedleConstraints();
    const NeedleCurve c = curve();
    const double l = m_s.needle.length_();
    for (size_t i = 0; i < m_history.size(); ++i) {
        const HistoryEntry& e = m_history[i];
        if (e.alpha < 0 || e.alpha > l || e.face == kNone) continue;
        const Vec3 target = c.point(e.alpha);
        ConstraintDesc d;
        d.priority = 1;
        if (slip) { // eq. 3.29: free along the needle axis
            Vec3 u, v;
            normalPlane(c.tangent(e.alpha), u, v);
            d.rows = {pointRow(e.face, e.xi, u, u.dot(target)), pointRow(e.face, e.xi, v, v.dot(target))};
        } else { // eq. 3.28
            for (int k = 0; k < 3; ++k)
                d.rows.push_back(pointRow(e.face, e.xi, Vec3::Unit(k), target[k]));
        }
        m_needleIds.push_back(m_fem->addConstraint(std::move(d)));
        m_needleEntryOf.push_back(static_cast<int>(i));
    }
}

void SutureSimulation::updateThreadConstraint(double pull, SutureStepStats& st) {
    // Outside segments: from an exit point to the next entry point along the thread [eq. 3.33].
    std::vector<std::pair<const HistoryEntry*, const HistoryEntry*>> segs;
    const HistoryEntry* lastExit = nullptr;
    for (const HistoryEntry& e : m_history) {
        if (e.alpha >= 0 || !e.puncture()) continue;
        if (e.exitsMesh)
            lastExit = &e;
        else if (e.entersMesh && lastExit) {
            segs.emplace_back(lastExit, &e);
            lastExit = nullptr;
        }
    }
    auto dropAll = [&] {
        for (int id : m_pullIds)
            m_fem->removeConstraint(id);
        m_pullIds.clear();
    };
    if (!(pull > 0) || segs.empty()) {
        dropAll();
        return;
    }
    // Smoothed lengths L_i and their gradients d̂_i (stabilized below ε) at the current positions.
    const double eps = m_s.thread.stabilization;
    std::vector<ThreadSegmentLinearization> lin(segs.size());
    double lengthNow = 0;
    for (size_t i = 0; i < segs.size(); ++i) {
        const auto& [a, b] = segs[i];
        lin[i] = linearizeThreadSegment(materialPoint(a->face, a->xi), materialPoint(b->face, b->xi), eps);
        lengthNow += lin[i].length;
    }
    if (!m_pullStarted || segs.size() != m_pullSegments) {
        // Engagement reference [eq. 3.33]: ℓ = outside length + slack when the pull starts; a new
        // segment (another stitch) re-bases it on the pull applied so far.
        m_pullStarted = true;
        m_pullSegments = segs.size();
        m_outsideLength0 = lengthNow + m_s.thread.slack + pull;
    }
    const double target = m_outsideLength0 - pull;
    st.threadEngaged = lengthNow >= target;
    if (!st.threadEngaged) { // slack: pure sliding of the thread, zero multiplier
        dropAll();
        return;
    }
    // Every segment is brought together by the same factor κ [eq. 3.37], one-sided per segment (a
    // thread does not push): d̂_i·(r_b − r_a) ≤ κ L_i − (L_i − d̂_i·d_i), written as ≥ with the signs flipped.
    const double kappa = std::clamp(target / lengthNow, 1.0 - m_s.thread.maxStrainPerStep, 1.0);
    if (m_pullIds.size() != segs.size()) {
        dropAll();
        for (size_t i = 0; i < segs.size(); ++i) {
            ConstraintDesc d;
            d.kind = ConstraintKind::Unilateral;
            d.priority = 2;
            d.rows = {ConstraintRow{}};
            m_pullIds.push_back(m_fem->addConstraint(std::move(d)));
        }
    }
    for (size_t i = 0; i < segs.size(); ++i) {
        const auto& [a, b] = segs[i];
        const ThreadSegmentLinearization& l = lin[i];
        ConstraintRow row;
        const auto va = m_mesh->halfFacetVertices(a->face), vb = m_mesh->halfFacetVertices(b->face);
        for (int k = 0; k < 3; ++k) {
            if (b->xi[k] != 0) row.terms.push_back({vb[k], -b->xi[k] * l.direction});
            if (a->xi[k] != 0) row.terms.push_back({va[k], a->xi[k] * l.direction});
        }
        row.b = -(kappa * l.length - l.offset);
        if (!n_finite(row)) row = ConstraintRow{};
        m_fem->setRows(m_pullIds[i], {row});
    }
}

void SutureSimulation::updateContacts() {
    // Tangential release [eq. 2.73]: one row along the current normal; drop contacts that slid off or
    // stayed released.
    const auto& x = m_fem->positions();
    for (auto it = m_contacts.begin(); it != m_contacts.end();) {
        Contact& c = *it;
        bool drop = false;
        const auto& v = c.c.v;
        ConstraintRow r;
        if (c.c.kind == CollisionKind::VertexFace) {
            Vec3 n = (x[v[2]] - x[v[1]]).cross(x[v[3]] - x[v[1]]);
            drop = !(n.norm() > 0);
            n = n.normalized();
            if (n.dot(c.c.normal) < 0) n = -n;
            c.c.normal = n;
            // Where does the vertex project now? Off the face: let the neighbours take over.
            const Vec3 p = x[v[0]] - n.dot(x[v[0]] - x[v[1]]) * n;
            const Vec3 e1 = x[v[2]] - x[v[1]], e2 = x[v[3]] - x[v[1]], q = p - x[v[1]];
            const double d00 = e1.dot(e1), d01 = e1.dot(e2), d11 = e2.dot(e2), d20 = q.dot(e1), d21 = q.dot(e2);
            const double den = d00 * d11 - d01 * d01;
            if (den > 0) {
                const double b1 = (d11 * d20 - d01 * d21) / den, b2 = (d00 * d21 - d01 * d20) / den;
                if (b1 < -0.25 || b2 < -0.25 || b1 + b2 > 1.25) drop = true;
            }
            r.terms = {{v[0], n}, {v[1], -c.c.w[0] * n}, {v[2], -c.c.w[1] * n}, {v[3], -c.c.w[2] * n}};
        } else {
            Vec3 n = (x[v[1]] - x[v[0]]).cross(x[v[3]] - x[v[2]]);
            drop = !(n.norm() > 1e-9 * (x[v[1]] - x[v[0]]).norm() * (x[v[3]] - x[v[2]]).norm());
            n = n.normalized();
            if (n.dot(c.c.normal) < 0) n = -n;
            c.c.normal = n;
            const double a = c.c.w[0], b = c.c.w[1];
            r.terms = {{v[0], (1 - a) * n}, {v[1], a * n}, {v[2], -(1 - b) * n}, {v[3], -b * n}};
        }
        r.b = 0;
        if (m_fem->hasConstraint(c.id)) {
            if (!m_fem->state(c.id).active)
                ++c.inactiveSteps;
            else
                c.inactiveSteps = 0;
            if (c.inactiveSteps > 3) drop = true;
        } else {
            drop = true;
        }
        if (drop || !n_finite(r)) {
            m_fem->removeConstraint(c.id);
            it = m_contacts.erase(it);
            continue;
        }
        m_fem->setRows(c.id, {r});
        ++it;
    }
}

void SutureSimulation::processContacts(const std::vector<Vec3>& before, SutureStepStats& st) {
    if (!m_detector) return;
    std::vector<Collision> hits;
    for (int round = 0; round < m_s.contactRounds; ++round) {
        hits.clear();
        m_detector->detect(before, m_fem->positions(), m_s.contactThickness, hits);
        // A collision already held (same primitives) is skipped; others sharing a vertex are kept
        // (redundant rows are rejected by the solve, [B §2.2.6]).
        std::set<std::array<int32_t, 5>> held;
        auto keyOf = [](const Collision& c) {
            return std::array<int32_t, 5>{static_cast<int32_t>(c.kind), c.v[0], c.v[1], c.v[2], c.v[3]};
        };
        for (const Contact& c : m_contacts)
            held.insert(keyOf(c.c));
        int added = 0;
        for (const Collision& h : hits) { // time order [B §3.3.1]
            if (added >= m_s.contactsPerRound || m_contacts.size() >= static_cast<size_t>(m_s.maxContacts)) break;
            if (!held.insert(keyOf(h)).second) continue;
            ConstraintDesc d;
            d.kind = ConstraintKind::Unilateral;
            d.priority = 3;
            const Vec3& n = h.normal;
            ConstraintRow r;
            if (h.kind == CollisionKind::VertexFace)
                r.terms = {{h.v[0], n}, {h.v[1], -h.w[0] * n}, {h.v[2], -h.w[1] * n}, {h.v[3], -h.w[2] * n}};
            else
                r.terms = {{h.v[0], (1 - h.w[0]) * n},
                           {h.v[1], h.w[0] * n},
                           {h.v[2], -(1 - h.w[1]) * n},
                           {h.v[3], -h.w[1] * n}};
            r.b = 0;
            if (!n_finite(r)) continue;
            d.rows = {r};
            Contact c;
            c.c = h;
            c.id = m_fem->addConstraint(std::move(d));
            m_contacts.push_back(c);
            ++added;
        }
        st.newContacts += added;
        if (added == 0) break;
        if (!solve(st)) return;
    }
}

void SutureSimulation::prefetchAhead(const std::vector<Vec3>& before) {
    if (!m_detector || m_s.contactLookaheadSteps <= 0 || m_steps % m_s.contactLookaheadEvery != 0) return;
    const auto& x = m_fem->positions();
    std::vector<Vec3> ahead(x.size());
    const double k = m_s.contactLookaheadSteps, cap = m_s.contactLookaheadDistance;
    for (size_t v = 0; v < x.size(); ++v) {
        Vec3 d = k * (x[v] - before[v]);
        const double len = d.norm();
        if (len > cap) d *= cap / len;
        ahead[v] = x[v] + d;
    }
    std::vector<Collision> hits;
    m_detector->detect(x, ahead, m_s.contactThickness, hits);
    std::vector<int32_t> nodes;
    for (const Collision& h : hits)
        nodes.insert(nodes.end(), h.v.begin(), h.v.end());
    m_fem->prefetchNodes(nodes);
}

void SutureSimulation::pinHistoryNodes() {
    // The thread's puncture points and the needle's entries will be constrained again (pull, slip):
    // their K⁻¹ columns stay cached instead of being recomputed in one burst when the pull engages.
    const double l = m_s.needle.length_();
    std::vector<int32_t> nodes;
    for (const HistoryEntry& e : m_history) {
        if (e.face == kNone || !(e.puncture() || (e.alpha >= 0 && e.alpha <= l))) continue;
        const auto v = m_mesh->halfFacetVertices(e.face);
        nodes.insert(nodes.end(), v.begin(), v.end());
    }
    m_fem->pinNodes(nodes);
}

bool SutureSimulation::n_finite(const ConstraintRow& r) {
    for (const auto& t : r.terms)
        if (!t.a.allFinite()) return false;
    return std::isfinite(r.b);
}

bool SutureSimulation::solve(SutureStepStats& st) {
    const FemSolveStats fs = m_fem->solve();
    ++st.solves;
    st.activeRows = fs.rows;
    st.rejectedRows = fs.redundant + fs.incompatible;
    st.refactored |= fs.refactored;
    st.refactorWaited |= fs.refactorWaited;
    st.substitutions += fs.substitutions;
    st.newCachedNodes += fs.newCachedNodes;
    st.activeSetIterations += fs.activeSetIterations;
    if (!fs.error.empty()) st.error = fs.error;
    if (!fs.finite) st.finite = false;
    return fs.finite;
}

void SutureSimulation::readForces(SutureStepStats& st) {
    Vec3 total = Vec3::Zero(); // force of the needle on the tissue = −Σ Cᵀλ over needle rows
    for (int id : m_needleIds) {
        const auto& d = m_fem->constraint(id);
        const auto& lam = m_fem->state(id).lambda;
        for (size_t r = 0; r < d.rows.size(); ++r) {
            Vec3 dir = Vec3::Zero();
            double w = 0;
            for (const auto& t : d.rows[r].terms) {
                dir += t.a;
                w += t.a.norm();
            }
            if (w > 0) total -= lam[r] * dir; // Σ_j ξ_j e = e: the row's direction
        }
    }
    if (m_tip.active && m_fem->hasConstraint(m_tip.id)) {
        const auto& lam = m_fem->state(m_tip.id).lambda;
        const Vec3 f(-lam[0], -lam[1], -lam[2]);
        total += f;
        st.tipAxialForce = f.dot(curve().tangent(m_s.needle.length_()));
    }
    st.needleForce = total.norm();
    st.needleForceVector = -total;
    double tension = 0;
    for (int id : m_pullIds)
        if (m_fem->hasConstraint(id) && m_fem->state(id).active && !m_fem->state(id).lambda.empty())
            tension = std::max(tension, -m_fem->state(id).lambda[0]);
    st.threadTension = tension; // the largest segment tension (frictionless: all segments equal ideally)
}

SutureStepStats SutureSimulation::step(const NeedleFrame& frame) {
    SutureStepStats st;
    ++m_steps;
    m_fem->beginStep();
    const std::vector<Vec3> before = m_fem->positions();
    const double l = m_s.needle.length_();
    Eigen::Isometry3d next = frame.pose;
    if (!finitePose(next) || !std::isfinite(frame.pull)) {
        st.error = "non-finite needle pose or pull ignored";
        next = m_pose;
    }
    const double pull = std::isfinite(frame.pull) ? std::max(0.0, frame.pull) : 0.0;
    const double sigma = slidingAmount(m_s.needle, m_pose, next);
    st.sigma = std::isfinite(sigma) ? sigma : 0.0;

    if (!m_tip.active) {
        Crossing hit;
        hit.face = kNone;
        if (st.sigma > 0) trackForward(needleCurve(m_s.needle, m_pose), st.sigma, true, st, &hit);
        if (hit.face != kNone) {
            // The tip touches a boundary facet: hold the touched point to the tip (§3.2.3).
            m_tip.active = true;
            m_tip.face = hit.face;
            m_tip.xi = hit.xi;
            // Playback starts from the pose before this step (tip still outside the facet).
            m_tip.contactPose = m_pose;
            m_tip.snapshot = m_history;
            m_tip.log.clear();
            shiftParameters(hit.alpha - l);
        } else {
            shiftParameters(st.sigma);
        }
    }
    if (m_tip.active) m_tip.log.push_back(next);
    m_pose = next;

    updateContacts();
    updateThreadConstraint(pull, st);
    if (m_tip.active) {
        const Vec3 tip = curve().point(l);
        ConstraintDesc d;
        d.priority = 0;
        for (int k = 0; k < 3; ++k)
            d.rows.push_back(pointRow(m_tip.face, m_tip.xi, Vec3::Unit(k), tip[k]));
        if (m_fem->hasConstraint(m_tip.id)) m_fem->removeConstraint(m_tip.id);
        m_tip.id = m_fem->addConstraint(std::move(d));
        addNeedleConstraints(true);
    } else {
        addNeedleConstraints(false);
    }
    solve(st);
    readForces(st);
    if (m_tip.active) {
        // Slip: the needle slid through the interior points; re-find their parameters (§3.2.4.1).
        const NeedleCurve c = curve();
        for (size_t k = 0; k < m_needleIds.size(); ++k) {
            HistoryEntry& e = m_history[m_needleEntryOf[k]];
            e.alpha = c.closestParameter(materialPoint(e.face, e.xi), 0, l);
        }
        const bool puncture = st.tipAxialForce > m_s.needle.punctureForce;
        const bool lost = st.tipAxialForce < 0;
        if (puncture || lost) {
            // Motion playback from the first contact (§3.2.3.1), through the facet when punctured.
            m_fem->removeConstraint(m_tip.id);
            m_tip.id = -1;
            m_tip.active = false;
            m_history = m_tip.snapshot;
            clearNeedleConstraints();
            solve(st); // the boundary snaps back before the playback tracks through it
            replay(m_tip.contactPose, m_tip.log, puncture, st);
            m_tip.log.clear();
            addNeedleConstraints(false);
            solve(st);
            readForces(st);
        }
    }
    st.tipInContact = m_tip.active;
    if (m_s.contact) {
        processContacts(before, st);
        prefetchAhead(before);
    }
    pinHistoryNodes();
    readForces(st);
    const FemSolveStats amortized = m_fem->endStep(); // carried columns and prefetch, in what the step left
    st.substitutions += amortized.substitutions;
    st.newCachedNodes += amortized.newCachedNodes;
    if (!amortized.error.empty()) st.error = amortized.error;
    for (const HistoryEntry& e : m_history) {
        if (e.alpha >= 0 && e.alpha <= l) ++st.needleEntries;
        if (e.alpha < 0) ++st.threadEntries;
    }
    st.punctures = m_punctures;
    st.contacts = static_cast<int>(m_contacts.size());
    return st;
}

} // namespace viscera::sim
