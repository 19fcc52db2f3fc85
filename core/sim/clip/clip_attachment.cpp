#include "sim/clip/clip_attachment.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace viscera::sim {

namespace {

[[noreturn]] void fail(const std::string& rule) {
    throw std::invalid_argument("sim::ClipAttachment::apply(): " + rule);
}

double radicalInverse(int i, int base) {
    double f = 1, r = 0;
    while (i > 0) {
        f /= base;
        r += f * (i % base);
        i /= base;
    }
    return r;
}

/// The first n Halton points (bases 2, 3, 5; index from 1) folded from the unit cube into the
/// reference tet (Rocchini–Cignoni), as barycentric coordinates.
std::vector<Eigen::Vector4d> barycentricPattern(int n) {
    std::vector<Eigen::Vector4d> out;
    for (int i = 1; i <= n; ++i) {
        double s = radicalInverse(i, 2), t = radicalInverse(i, 3), u = radicalInverse(i, 5);
        if (s + t > 1) { // fold the cube into the prism s + t <= 1
            s = 1 - s;
            t = 1 - t;
        }
        if (t + u > 1) { // fold the prism into the tet s + t + u <= 1
            const double tmp = u;
            u = 1 - s - t;
            t = 1 - tmp;
        } else if (s + t + u > 1) {
            const double tmp = u;
            u = s + t + u - 1;
            s = 1 - t - tmp;
        }
        out.emplace_back(1 - s - t - u, s, t, u);
    }
    return out;
}

Vec3 baryPoint(const std::vector<Vec3>& x, const AuxiliaryNode& a) {
    return a.bary[0] * x[a.nodes[0]] + a.bary[1] * x[a.nodes[1]] + a.bary[2] * x[a.nodes[2]] +
           a.bary[3] * x[a.nodes[3]];
}

bool allFinite(const std::vector<Vec3>& v) {
    return std::all_of(v.begin(), v.end(), [](const Vec3& p) { return p.allFinite(); });
}

} // namespace

// ---- bounds ----------------------------------------------------------------------------------

ClipBounds ClipBounds::box(const Vec3& centre, const Mat3& axes, const Vec3& halfExtents) {
    ClipBounds b;
    b.centre = centre;
    b.axes = axes;
    b.halfExtents = halfExtents;
    return b;
}

ClipBounds ClipBounds::sphere(const Vec3& centre, double radius) {
    ClipBounds b;
    b.centre = centre;
    b.radius = radius;
    return b;
}

bool ClipBounds::contains(const Vec3& p) const {
    if (isSphere()) return (p - centre).squaredNorm() <= radius * radius;
    const Vec3 l = axes.transpose() * (p - centre);
    return std::abs(l.x()) <= halfExtents.x() && std::abs(l.y()) <= halfExtents.y() &&
           std::abs(l.z()) <= halfExtents.z();
}

double ClipBounds::normalisedDistance(const Vec3& p) const {
    if (isSphere()) return (p - centre).norm() / radius;
    const Vec3 l = axes.transpose() * (p - centre);
    return l.cwiseQuotient(halfExtents).norm() / std::sqrt(3.0);
}

// ---- application -----------------------------------------------------------------------------

std::unique_ptr<ClipAttachment> ClipAttachment::apply(const TetMesh& vessel, const std::vector<Vec3>& x,
                                                      const ClipDesc& clip, const ClipSettings& settings) {
    const size_t nv = vessel.vertexCount();
    if (x.size() != nv)
        fail("positions has " + std::to_string(x.size()) + " entries, the vessel mesh " + std::to_string(nv) +
             " vertices");
    for (size_t i = 0; i < nv; ++i)
        if (!x[i].allFinite()) fail("positions[" + std::to_string(i) + "] is not finite");
    const ClipBounds& b = clip.bounds;
    if (!b.centre.allFinite()) fail("bounds.centre is not finite");
    if (!(b.radius >= 0)) fail("bounds.radius must be 0 (box) or positive (sphere)");
    if (b.isSphere()) {
        if (!std::isfinite(b.radius)) fail("bounds.radius is not finite");
    } else {
        if (!(b.halfExtents.minCoeff() > 0) || !b.halfExtents.allFinite())
            fail("bounds.halfExtents must be finite and positive (or give a sphere radius)");
        if (!b.axes.allFinite() || !((b.axes.transpose() * b.axes - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-6))
            fail("bounds.axes must be orthonormal columns");
    }
    if (!allFinite(clip.vertices)) fail("a clip vertex is not finite");
    if (!allFinite(clip.contactPoints)) fail("a clip contact point is not finite");
    if (!clip.jawNormal.allFinite() || !(clip.jawNormal.norm() > 1e-12)) fail("jawNormal must be finite and non-zero");
    if (settings.auxiliaryPerTet < 0 || settings.auxiliaryPerTet > 64)
        fail("settings.auxiliaryPerTet must be in [0, 64]");
    if (!(settings.weightFloor > 0 && settings.weightFloor <= 1)) fail("settings.weightFloor must be in (0, 1]");
    if (settings.rotation.maxIterations < 0 || !(settings.rotation.epsilon > 0) || !(settings.rotation.tolerance >= 0))
        fail("settings.rotation needs maxIterations >= 0, epsilon > 0, tolerance >= 0");

    std::unique_ptr<ClipAttachment> c(new ClipAttachment());
    c->m_settings = settings;
    c->m_vertexCount = nv;
    const double f = settings.weightFloor;
    auto weight = [&](const Vec3& p) {
        const double s2 = std::min(1.0, std::pow(b.normalisedDistance(p), 2));
        return f + (1 - f) * (1 - s2) * (1 - s2);
    };
    std::vector<Vec3> rest; // X′, same order as the weights
    const std::vector<Vec3>& X = vessel.positions();
    for (size_t v = 0; v < nv; ++v)
        if (b.contains(x[v])) {
            c->m_regionVertices.push_back(static_cast<int32_t>(v));
            c->m_weights.push_back(weight(x[v]));
            rest.push_back(X[v]);
        }
    const auto pattern = barycentricPattern(settings.auxiliaryPerTet);
    const auto& tets = vessel.tets();
    for (size_t t = 0; t < tets.size(); ++t)
        for (const auto& bary : pattern) {
            AuxiliaryNode a;
            a.tet = static_cast<int32_t>(t);
            for (int k = 0; k < 4; ++k)
                a.nodes[k] = tets[t][k];
            a.bary = bary;
            const Vec3 p = baryPoint(x, a);
            if (!b.contains(p)) continue;
            c->m_weights.push_back(weight(p));
            rest.push_back(baryPoint(X, a));
            c->m_aux.push_back(a);
        }
    if (rest.empty())
        fail("the clip bounds contain no vessel vertex and no auxiliary node (enlarge the bounds "
             "or raise settings.auxiliaryPerTet)");

    // Rest centre, offsets and the pseudo-inverse of the rest covariance (constant).
    double W = 0;
    Vec3 Xcm = Vec3::Zero();
    for (size_t i = 0; i < rest.size(); ++i) {
        W += c->m_weights[i];
        Xcm += c->m_weights[i] * rest[i];
    }
    Xcm /= W;
    c->m_weightSum = W;
    c->m_restCentre = Xcm;
    Mat3 Aqq = Mat3::Zero();
    c->m_restOffsets.resize(rest.size());
    for (size_t i = 0; i < rest.size(); ++i) {
        const Vec3 q = rest[i] - Xcm;
        c->m_restOffsets[i] = q;
        c->m_offsetSum += c->m_weights[i] * q;
        Aqq += c->m_weights[i] * q * q.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Mat3> eig(Aqq);
    const Vec3 lam = eig.eigenvalues();
    const double lmax = std::max(0.0, lam.maxCoeff());
    Vec3 inv = Vec3::Zero();
    for (int k = 0; k < 3; ++k)
        if (lmax > 0 && lam[k] > 1e-6 * lmax) {
            inv[k] = 1.0 / lam[k];
            ++c->m_rank;
        }
    c->m_AqqPinv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();

    // Application pose: centre and R₀ (polar decomposition, then the exp-map fixed point so that
    // the per-frame update starts exactly where it would settle).
    Mat3 Apq;
    c->accumulate(x, c->m_restCentre, c->m_centre0, Apq);
    c->m_centre = c->m_centre0;
    c->m_A = Apq * c->m_AqqPinv;
    c->m_R0 = polarRotation(c->m_A);
    ExpMapOptions settle = settings.rotation;
    settle.maxIterations = 100;
    settle.tolerance = 0;
    refineRotationExpMap(c->m_A, c->m_R0, settle);
    c->m_R = c->m_R0;

    c->m_jawNormal0 = clip.jawNormal.normalized();
    c->m_vertices0 = clip.vertices;
    c->m_contacts0 = clip.contactPoints;
    c->m_vertices = clip.vertices;
    c->m_contacts = clip.contactPoints;
    return c;
}

// ---- per frame -------------------------------------------------------------------------------

bool ClipAttachment::accumulate(const std::vector<Vec3>& x, const Vec3& ref, Vec3& centre, Mat3& Apq) const {
    // One pass: Σ w (x′ − ref) and Σ w (x′ − ref)(X′ − X′_cm)ᵀ about a reference point near the
    // region (conditioning); then Σ w (x′ − x′_cm) qᵀ = Σ w (x′ − ref) qᵀ − (x′_cm − ref) Σ w qᵀ,
    // with Σ w q (zero up to round-off) stored at application, so the result is eq. 5.15's.
    const size_t nv = m_regionVertices.size();
    Vec3 s = Vec3::Zero();
    Mat3 P = Mat3::Zero();
    for (size_t i = 0; i < nv; ++i) {
        const Vec3 d = m_weights[i] * (x[m_regionVertices[i]] - ref);
        s += d;
        P += d * m_restOffsets[i].transpose();
    }
    for (size_t j = 0; j < m_aux.size(); ++j) {
        const Vec3 d = m_weights[nv + j] * (baryPoint(x, m_aux[j]) - ref);
        s += d;
        P += d * m_restOffsets[nv + j].transpose();
    }
    const Vec3 shift = s / m_weightSum;
    centre = ref + shift;
    Apq = P - shift * m_offsetSum.transpose();
    return centre.allFinite() && Apq.allFinite();
}

ClipUpdateStatus ClipAttachment::update(const std::vector<Vec3>& x) {
    if (x.size() != m_vertexCount) {
        ++m_rejected;
        return ClipUpdateStatus::SizeMismatch;
    }
    Vec3 centre;
    Mat3 Apq;
    if (!accumulate(x, m_centre, centre, Apq)) {
        ++m_rejected;
        return ClipUpdateStatus::NonFiniteInput;
    }
    const Mat3 A = Apq * m_AqqPinv;
    if (!A.allFinite()) {
        ++m_rejected;
        return ClipUpdateStatus::NonFiniteInput;
    }
    m_centre = centre;
    m_A = A;
    m_lastIterations = refineRotationExpMap(m_A, m_R, m_settings.rotation);
    if ((m_R.transpose() * m_A).trace() < 0) {
        // Warm start more than 90° away (a flip within one frame): re-seed from the polar
        // decomposition and polish with the exp-map update.
        m_R = polarRotation(m_A);
        refineRotationExpMap(m_A, m_R, m_settings.rotation);
        ++m_fallbacks;
    }
    placeClipPoints();
    return ClipUpdateStatus::Ok;
}

Vec3 ClipAttachment::transformPoint(const Vec3& p0) const {
    return relativeRotation() * (p0 - m_centre0) + m_centre;
}

void ClipAttachment::placeClipPoints() {
    const Mat3 Q = relativeRotation();
    for (size_t i = 0; i < m_vertices0.size(); ++i)
        m_vertices[i] = Q * (m_vertices0[i] - m_centre0) + m_centre;
    for (size_t i = 0; i < m_contacts0.size(); ++i)
        m_contacts[i] = Q * (m_contacts0[i] - m_centre0) + m_centre;
}

void ClipAttachment::auxiliaryPositionsInto(const std::vector<Vec3>& x, std::vector<Vec3>& out) const {
    if (x.size() != m_vertexCount)
        throw std::invalid_argument("sim::ClipAttachment::auxiliaryPositionsInto(): positions has " +
                                    std::to_string(x.size()) + " entries, expected " + std::to_string(m_vertexCount));
    out.resize(m_aux.size());
    for (size_t j = 0; j < m_aux.size(); ++j)
        out[j] = baryPoint(x, m_aux[j]);
}

} // namespace viscera::sim
