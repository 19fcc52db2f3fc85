#include "sim/contact/ccd.hpp"

#include "sim/collision/distance.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace viscera::sim {
namespace {

/// Roots in [0, 1] of k0 + k1 t + k2 t² + k3 t³, ascending (bisection on monotone pieces).
int cubicRoots01(const double k[4], double out[3]) {
    auto f = [&](double t) { return ((k[3] * t + k[2]) * t + k[1]) * t + k[0]; };
    // Split [0, 1] at the roots of the derivative k1 + 2k2 t + 3k3 t².
    double cuts[4] = {0, 0, 0, 1};
    int nc = 1;
    const double a = 3 * k[3], b = 2 * k[2], c = k[1];
    if (std::abs(a) > 1e-300) {
        const double disc = b * b - 4 * a * c;
        if (disc >= 0) {
            const double sq = std::sqrt(disc);
            double r1 = (-b - sq) / (2 * a), r2 = (-b + sq) / (2 * a);
            if (r1 > r2) std::swap(r1, r2);
            if (r1 > 0 && r1 < 1) cuts[nc++] = r1;
            if (r2 > 0 && r2 < 1) cuts[nc++] = r2;
        }
    } else if (std::abs(b) > 1e-300) {
        const double r = -c / b;
        if (r > 0 && r < 1) cuts[nc++] = r;
    }
    cuts[nc++] = 1;
    std::sort(cuts, cuts + nc);
    const double scale = std::abs(k[0]) + std::abs(k[1]) + std::abs(k[2]) + std::abs(k[3]);
    const double eps = 1e-14 * scale;
    int n = 0;
    for (int i = 0; i + 1 < nc; ++i) {
        double lo = cuts[i], hi = cuts[i + 1];
        double flo = f(lo), fhi = f(hi);
        if (std::abs(flo) <= eps) {
            if (n == 0 || out[n - 1] < lo - 1e-12) out[n++] = lo;
            continue;
        }
        if (std::abs(fhi) <= eps) {
            out[n++] = hi;
            continue;
        }
        if ((flo < 0) == (fhi < 0)) continue;
        for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi), fm = f(mid);
            if ((fm < 0) == (flo < 0)) {
                lo = mid;
                flo = fm;
            } else {
                hi = mid;
            }
        }
        out[n++] = 0.5 * (lo + hi);
        if (n == 3) break;
    }
    return n;
}

/// Coplanarity cubic of four linearly moving points: ((x1−x0) × (x2−x0)) · (x3−x0).
void coplanarity(const std::array<Vec3, 4>& p0, const std::array<Vec3, 4>& p1, int o, int a, int b, int c,
                 double k[4]) {
    const Vec3 e1 = p0[a] - p0[o], e2 = p0[b] - p0[o], e3 = p0[c] - p0[o];
    const Vec3 d1 = (p1[a] - p1[o]) - e1, d2 = (p1[b] - p1[o]) - e2, d3 = (p1[c] - p1[o]) - e3;
    const Vec3 c0 = e1.cross(e2), c1 = e1.cross(d2) + d1.cross(e2), c2 = d1.cross(d2);
    k[0] = c0.dot(e3);
    k[1] = c0.dot(d3) + c1.dot(e3);
    k[2] = c1.dot(d3) + c2.dot(e3);
    k[3] = c2.dot(d3);
}

std::array<Vec3, 4> lerp(const std::array<Vec3, 4>& a, const std::array<Vec3, 4>& b, double t) {
    return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]), a[3] + t * (b[3] - a[3])};
}

/// Closest point on triangle (a, b, c) to p as barycentric coordinates.
Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double v = d1 / (d1 - d3);
        return {1 - v, v, 0};
    }
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double w = d2 / (d2 - d6);
        return {1 - w, 0, w};
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return {0, 1 - w, w};
    }
    const double denom = 1.0 / (va + vb + vc);
    const double v = vb * denom, w = vc * denom;
    return {1 - v - w, v, w};
}

/// Closest points of segments (p0, p1) and (q0, q1): parameters (s, t) in [0, 1].

} // namespace

bool vertexFaceCcd(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, double thickness, double& t, Vec3& w) {
    double k[4], roots[3];
    coplanarity(x0, x1, 1, 2, 3, 0, k); // ((b−a) × (c−a)) · (p−a), p = index 0
    const int n = cubicRoots01(k, roots);
    for (int i = 0; i < n; ++i) {
        const auto x = lerp(x0, x1, roots[i]);
        const Vec3 bc = closestOnTriangle(x[0], x[1], x[2], x[3]);
        const Vec3 q = bc[0] * x[1] + bc[1] * x[2] + bc[2] * x[3];
        if ((q - x[0]).norm() <= thickness) {
            t = roots[i];
            w = bc;
            return true;
        }
    }
    return false;
}

bool edgeEdgeCcd(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, double thickness, double& t, Vec3& w) {
    double k[4], roots[3];
    coplanarity(x0, x1, 0, 1, 2, 3, k);
    const int n = cubicRoots01(k, roots);
    for (int i = 0; i < n; ++i) {
        const auto x = lerp(x0, x1, roots[i]);
        double s, u;
        const SegmentPair closest = closestPointsSegments(x[0], x[1], x[2], x[3]);
        s = closest.s;
        u = closest.t;
        const Vec3 p = x[0] + s * (x[1] - x[0]), q = x[2] + u * (x[3] - x[2]);
        if ((p - q).norm() <= thickness && s > 0 && s < 1 && u > 0 && u < 1) {
            t = roots[i];
            w = Vec3(s, u, 0);
            return true;
        }
    }
    return false;
}

ContactDetector::ContactDetector(const TetMesh& mesh, bool selfContact) : m_selfContact(selfContact) {
    if (mesh.level() < 3)
        throw std::logic_error("sim::ContactDetector(): requires adjacency level 3; call mesh.requireLevel(3) first");
    // Bodies: connected components of the tets (union–find).
    std::vector<int32_t> parent(mesh.vertexCount());
    for (size_t i = 0; i < parent.size(); ++i)
        parent[i] = static_cast<int32_t>(i);
    auto root = [&](int32_t v) {
        while (parent[v] != v)
            v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const Tet& t : mesh.tets())
        for (int k = 1; k < 4; ++k)
            parent[root(t[k])] = root(t[0]);
    m_body.resize(parent.size());
    std::map<int32_t, int> bodyIndex;
    for (size_t i = 0; i < parent.size(); ++i) {
        const int32_t r = root(static_cast<int32_t>(i));
        m_body[i] = bodyIndex.emplace(r, static_cast<int>(bodyIndex.size())).first->second;
    }
    const TriMesh& b = mesh.boundary();
    const auto& vmap = mesh.boundaryVertexMap();
    std::map<std::pair<int32_t, int32_t>, int> edges;
    std::vector<Vec3> tc, ec;
    const auto& x = mesh.positions();
    for (const Tri& t : b.triangles()) {
        const std::array<int32_t, 3> v = {vmap[t[0]], vmap[t[1]], vmap[t[2]]};
        m_tris.push_back(v);
        tc.push_back((x[v[0]] + x[v[1]] + x[v[2]]) / 3.0);
        for (int k = 0; k < 3; ++k) {
            const int32_t a = std::min(v[k], v[(k + 1) % 3]), c = std::max(v[k], v[(k + 1) % 3]);
            if (edges.emplace(std::make_pair(a, c), 0).second) {
                m_edges.push_back({a, c});
                ec.push_back(0.5 * (x[a] + x[c]));
            }
        }
    }
    m_verts = vmap;
    // One tree per body: between-body queries never descend into the querying body's own tree.
    const int bodies = m_selfContact ? 1 : static_cast<int>(bodyIndex.size());
    m_triTrees.assign(bodies, {});
    m_edgeTrees.assign(bodies, {});
    std::vector<std::vector<int>> triIds(bodies), edgeIds(bodies);
    for (size_t i = 0; i < m_tris.size(); ++i)
        triIds[m_selfContact ? 0 : m_body[m_tris[i][0]]].push_back(static_cast<int>(i));
    for (size_t i = 0; i < m_edges.size(); ++i)
        edgeIds[m_selfContact ? 0 : m_body[m_edges[i][0]]].push_back(static_cast<int>(i));
    for (int b = 0; b < bodies; ++b) {
        build(m_triTrees[b], tc, std::move(triIds[b]));
        build(m_edgeTrees[b], ec, std::move(edgeIds[b]));
    }
}

void ContactDetector::build(Tree& tree, const std::vector<Vec3>& c, std::vector<int> ids) {
    tree.order = std::move(ids);
    tree.nodes.clear();
    if (tree.order.empty()) return;
    struct Job {
        int node, first, count;
    };
    tree.nodes.push_back({});
    std::vector<Job> stack = {{0, 0, static_cast<int>(tree.order.size())}};
    while (!stack.empty()) {
        const Job j = stack.back();
        stack.pop_back();
        if (j.count <= 4) {
            tree.nodes[j.node].first = j.first;
            tree.nodes[j.node].count = j.count;
            continue;
        }
        Eigen::AlignedBox3d box;
        for (int i = 0; i < j.count; ++i)
            box.extend(c[tree.order[j.first + i]]);
        int axis;
        box.sizes().maxCoeff(&axis);
        const int half = j.count / 2;
        std::nth_element(tree.order.begin() + j.first, tree.order.begin() + j.first + half,
                         tree.order.begin() + j.first + j.count, [&](int a, int b) { return c[a][axis] < c[b][axis]; });
        const int l = static_cast<int>(tree.nodes.size());
        tree.nodes.push_back({});
        tree.nodes.push_back({});
        tree.nodes[j.node].left = l;
        tree.nodes[j.node].right = l + 1;
        stack.push_back({l, j.first, half});
        stack.push_back({l + 1, j.first + half, j.count - half});
    }
}

template <class BoxOf> void ContactDetector::refit(Tree& tree, BoxOf&& boxOf) {
    // Children are stored after their parent: a reverse sweep refits bottom-up.
    for (int i = static_cast<int>(tree.nodes.size()) - 1; i >= 0; --i) {
        Node& n = tree.nodes[i];
        n.box.setEmpty();
        if (n.left < 0) {
            for (int k = 0; k < n.count; ++k)
                n.box.extend(boxOf(tree.order[n.first + k]));
        } else {
            n.box.extend(tree.nodes[n.left].box);
            n.box.extend(tree.nodes[n.right].box);
        }
    }
}

void ContactDetector::detect(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1, double thickness,
                             std::vector<Collision>& out) {
    m_candidates = 0;
    const size_t first = out.size();
    const Vec3 pad = Vec3::Constant(thickness);
    auto swept = [&](std::initializer_list<int32_t> vs) {
        Eigen::AlignedBox3d b;
        for (int32_t v : vs) {
            b.extend(x0[v]);
            b.extend(x1[v]);
        }
        b.min() -= pad;
        b.max() += pad;
        return b;
    };
    for (Tree& t : m_triTrees)
        refit(t, [&](int i) { return swept({m_tris[i][0], m_tris[i][1], m_tris[i][2]}); });
    for (Tree& t : m_edgeTrees)
        refit(t, [&](int i) { return swept({m_edges[i][0], m_edges[i][1]}); });
    const int bodies = static_cast<int>(m_triTrees.size());
    std::vector<int> stack;
    auto query = [&](const Tree& tree, const Eigen::AlignedBox3d& q, auto&& visit) {
        if (tree.nodes.empty()) return;
        stack.assign(1, 0);
        while (!stack.empty()) {
            const Node& n = tree.nodes[stack.back()];
            stack.pop_back();
            if (!n.box.intersects(q)) continue;
            if (n.left < 0) {
                for (int k = 0; k < n.count; ++k)
                    visit(tree.order[n.first + k]);
            } else {
                stack.push_back(n.left);
                stack.push_back(n.right);
            }
        }
    };
    // Vertex–face.
    for (int32_t v : m_verts) {
        const Eigen::AlignedBox3d q = swept({v});
        for (int tb = 0; tb < bodies; ++tb) {
            if (!m_selfContact && tb == m_body[v]) continue;
            query(m_triTrees[tb], q, [&](int ti) {
                const auto& f = m_tris[ti];
                if (f[0] == v || f[1] == v || f[2] == v) return;
                if (!m_selfContact && m_body[f[0]] == m_body[v]) return;
                ++m_candidates;
                const std::array<Vec3, 4> a = {x0[v], x0[f[0]], x0[f[1]], x0[f[2]]};
                const std::array<Vec3, 4> b = {x1[v], x1[f[0]], x1[f[1]], x1[f[2]]};
                Collision c;
                if (!vertexFaceCcd(a, b, thickness, c.t, c.w)) return;
                c.kind = CollisionKind::VertexFace;
                c.v = {v, f[0], f[1], f[2]};
                const auto x = lerp(a, b, c.t);
                Vec3 n = (x[2] - x[1]).cross(x[3] - x[1]);
                if (!(n.norm() > 0)) return;
                n.normalize();
                const Vec3 rel0 = a[0] - (c.w[0] * a[1] + c.w[1] * a[2] + c.w[2] * a[3]);
                const Vec3 rel1 = b[0] - (c.w[0] * b[1] + c.w[1] * b[2] + c.w[2] * b[3]);
                const double side =
                    std::abs(n.dot(rel0)) > 1e-12 * (1 + rel0.norm()) ? n.dot(rel0) : -n.dot(rel1 - rel0);
                c.normal = side >= 0 ? n : Vec3(-n);
                out.push_back(c);
            });
        }
    }
    // Edge–edge (each unordered pair once).
    for (size_t ei = 0; ei < m_edges.size(); ++ei) {
        const auto& e = m_edges[ei];
        const Eigen::AlignedBox3d q = swept({e[0], e[1]});
        for (int tb = 0; tb < bodies; ++tb) {
            if (!m_selfContact && tb <= m_body[e[0]]) continue; // each pair of bodies once
            query(m_edgeTrees[tb], q, [&](int ej) {
                if (m_selfContact && static_cast<size_t>(ej) <= ei) return;
                const auto& g = m_edges[ej];
                if (g[0] == e[0] || g[0] == e[1] || g[1] == e[0] || g[1] == e[1]) return;
                if (!m_selfContact && m_body[g[0]] == m_body[e[0]]) return;
                ++m_candidates;
                const std::array<Vec3, 4> a = {x0[e[0]], x0[e[1]], x0[g[0]], x0[g[1]]};
                const std::array<Vec3, 4> b = {x1[e[0]], x1[e[1]], x1[g[0]], x1[g[1]]};
                Collision c;
                if (!edgeEdgeCcd(a, b, thickness, c.t, c.w)) return;
                c.kind = CollisionKind::EdgeEdge;
                c.v = {e[0], e[1], g[0], g[1]};
                const auto x = lerp(a, b, c.t);
                Vec3 n = (x[1] - x[0]).cross(x[3] - x[2]);
                if (!(n.norm() > 1e-12 * (x[1] - x[0]).norm() * (x[3] - x[2]).norm()))
                    return; // parallel: VF handles it
                n.normalize();
                auto sep = [&](const std::array<Vec3, 4>& p) {
                    return (p[0] + c.w[0] * (p[1] - p[0])) - (p[2] + c.w[1] * (p[3] - p[2]));
                };
                const Vec3 r0 = sep(a), r1 = sep(b);
                const double side = std::abs(n.dot(r0)) > 1e-12 * (1 + r0.norm()) ? n.dot(r0) : -n.dot(r1 - r0);
                c.normal = side >= 0 ? n : Vec3(-n);
                out.push_back(c);
            });
        }
    }
    std::sort(out.begin() + static_cast<long>(first), out.end(),
              [](const Collision& a, const Collision& b) { return a.t < b.t; });
}

} // namespace viscera::sim
