#include "render/sample_map.hpp"

#include "sim/collision/distance.hpp"
#include "sim/util/format.hpp"
#include "sim/util/line_reader.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace viscera::render {
namespace {

Eigen::Vector3d restOf(const RenderMesh& m, uint32_t v) {
    return {m.rest[3 * v], m.rest[3 * v + 1], m.rest[3 * v + 2]};
}

Eigen::Vector3d faceNormal(const RenderMesh& m, size_t f) {
    const Eigen::Vector3d a = restOf(m, m.indices[3 * f]), b = restOf(m, m.indices[3 * f + 1]),
                          c = restOf(m, m.indices[3 * f + 2]);
    return (b - a).cross(c - a);
}

std::string className(int samples) {
    return "samples must be 0, 1, 4 or 8, got " + std::to_string(samples);
}

} // namespace

bool isSampleClass(int samples) {
    return samples == 0 || samples == 1 || samples == 4 || samples == 8;
}

namespace {

/// The faces a fill from `seedFace` reaches (fillSampleClass's rule), one flag per face.
std::vector<uint8_t> fillFaces(const RenderMesh& mesh, size_t seedFace, float maxAngleDeg,
                               const std::vector<int32_t>& faceIsland) {
    const size_t faces = mesh.triangleCount();
    // faces around each undirected edge
    std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> edgeFaces;
    for (size_t f = 0; f < faces; ++f)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = mesh.indices[3 * f + k], b = mesh.indices[3 * f + (k + 1) % 3];
            if (a > b) std::swap(a, b);
            edgeFaces[{a, b}].push_back(f);
        }
    const double cosMax = std::cos(maxAngleDeg * 3.14159265358979323846 / 180.0);
    std::vector<uint8_t> reached(faces, 0);
    std::vector<size_t> stack{seedFace};
    reached[seedFace] = 1;
    while (!stack.empty()) {
        const size_t f = stack.back();
        stack.pop_back();
        const Eigen::Vector3d nf = faceNormal(mesh, f);
        for (int k = 0; k < 3; ++k) {
            uint32_t a = mesh.indices[3 * f + k], b = mesh.indices[3 * f + (k + 1) % 3];
            if (a > b) std::swap(a, b);
            for (size_t g : edgeFaces[{a, b}]) {
                if (reached[g]) continue;
                if (!faceIsland.empty() && faceIsland[g] != faceIsland[f]) continue; // UV border
                const Eigen::Vector3d ng = faceNormal(mesh, g);
                const double denom = nf.norm() * ng.norm();
                if (!(denom > 0) || nf.dot(ng) / denom < cosMax - 1e-12) continue; // sharp edge
                reached[g] = 1;
                stack.push_back(g);
            }
        }
    }
    return reached;
}

} // namespace

size_t fillSampleClass(RenderMesh& mesh, size_t seedFace, int samples, float maxAngleDeg,
                       const std::vector<int32_t>& faceIsland) {
    const std::string origin = "render::fillSampleClass(): mesh " + mesh.name + ": ";
    if (!isSampleClass(samples)) throw std::invalid_argument(origin + className(samples));
    const size_t faces = mesh.triangleCount();
    if (seedFace >= faces)
        throw std::invalid_argument(origin + "face " + std::to_string(seedFace) + " is out of range (" +
                                    std::to_string(faces) + " faces)");
    if (!(maxAngleDeg >= 0 && maxAngleDeg <= 180))
        throw std::invalid_argument(origin + "the angle must be in [0, 180] degrees, got " +
                                    std::to_string(maxAngleDeg));
    if (!faceIsland.empty() && faceIsland.size() != faces)
        throw std::invalid_argument(origin + std::to_string(faceIsland.size()) + " island ids for " +
                                    std::to_string(faces) + " faces");
    const std::vector<uint8_t> reached = fillFaces(mesh, seedFace, maxAngleDeg, faceIsland);
    if (mesh.sampleMap.size() != mesh.vertexCount()) mesh.sampleMap.assign(mesh.vertexCount(), 0.0f);
    size_t count = 0;
    for (size_t f = 0; f < faces; ++f)
        if (reached[f]) {
            ++count;
            for (int k = 0; k < 3; ++k)
                mesh.sampleMap[mesh.indices[3 * f + k]] = static_cast<float>(samples);
        }
    ++mesh.staticRevision;
    return count;
}

std::array<double, 4> sampleClassAreas(const RenderMesh& mesh) {
    std::array<double, 4> area{0, 0, 0, 0};
    auto slot = [](float s) { return s >= 7.5f ? 3 : s >= 3.5f ? 2 : s >= 0.5f ? 1 : 0; };
    for (size_t f = 0; f < mesh.triangleCount(); ++f) {
        const double a = 0.5 * faceNormal(mesh, f).norm() / 3.0;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = mesh.indices[3 * f + k];
            area[slot(v < mesh.sampleMap.size() ? mesh.sampleMap[v] : 0.0f)] += a;
        }
    }
    return area;
}

void validateSamplePaintOp(const SamplePaintOp& op, const std::string& what) {
    auto fail = [&](const std::string& rule) { throw std::invalid_argument(what + ": " + rule); };
    if (!isSampleClass(op.samples)) fail(className(op.samples));
    if (op.points.empty())
        fail(op.tool == SamplePaintOp::Tool::Fill ? "a fill needs its seed point" : "a stroke needs at least one dab");
    if (op.tool == SamplePaintOp::Tool::Fill && op.points.size() != 1)
        fail("a fill has one seed point, got " + std::to_string(op.points.size()));
    for (size_t k = 0; k < op.points.size(); ++k)
        if (!op.points[k].allFinite()) fail("point " + std::to_string(k) + " is not finite");
    if (op.tool == SamplePaintOp::Tool::Brush && !(std::isfinite(op.radius) && op.radius > 0))
        fail("radius must be finite and > 0, got " + sim::formatNumber(op.radius));
    if (op.tool == SamplePaintOp::Tool::Fill && !(op.maxAngleDeg >= 0 && op.maxAngleDeg <= 180))
        fail("the angle must be in [0, 180] degrees, got " + sim::formatNumber(op.maxAngleDeg));
}

size_t paintSampleBrush(RenderMesh& mesh, const std::vector<Eigen::Vector3d>& points, double radius, int samples) {
    if (!isSampleClass(samples))
        throw std::invalid_argument("render::paintSampleBrush(): mesh " + mesh.name + ": " + className(samples));
    if (mesh.sampleMap.size() != mesh.vertexCount()) mesh.sampleMap.assign(mesh.vertexCount(), 0.0f);
    const double r2 = radius * radius;
    size_t set = 0;
    for (size_t v = 0; v < mesh.vertexCount(); ++v) {
        const Eigen::Vector3d p = restOf(mesh, uint32_t(v));
        for (const Eigen::Vector3d& c : points)
            if ((p - c).squaredNorm() <= r2) {
                mesh.sampleMap[v] = static_cast<float>(samples);
                ++set;
                break;
            }
    }
    if (set) ++mesh.staticRevision;
    return set;
}

size_t nearestFace(const RenderMesh& mesh, const Eigen::Vector3d& p) {
    if (mesh.triangleCount() == 0)
        throw std::invalid_argument("render::nearestFace(): mesh " + mesh.name + " has no faces");
    size_t best = 0;
    double bestD = std::numeric_limits<double>::infinity();
    for (size_t f = 0; f < mesh.triangleCount(); ++f) {
        const sim::TrianglePoint q =
            sim::closestPointOnTriangle(p, restOf(mesh, mesh.indices[3 * f]), restOf(mesh, mesh.indices[3 * f + 1]),
                                        restOf(mesh, mesh.indices[3 * f + 2]));
        const double d = (q.point - p).squaredNorm();
        if (d < bestD) bestD = d, best = f;
    }
    return best;
}

void applySamplePaint(RenderMesh& mesh, const std::vector<SamplePaintOp>& ops, const std::vector<int32_t>& faceIsland) {
    for (size_t k = 0; k < ops.size(); ++k)
        validateSamplePaintOp(ops[k],
                              "render::applySamplePaint(): mesh " + mesh.name + ": operation " + std::to_string(k));
    const size_t faces = mesh.triangleCount(), verts = mesh.vertexCount();
    if (!faceIsland.empty() && faceIsland.size() != faces)
        throw std::invalid_argument("render::applySamplePaint(): mesh " + mesh.name + ": " +
                                    std::to_string(faceIsland.size()) + " island ids for " + std::to_string(faces) +
                                    " faces");
    mesh.sampleMap.assign(verts, 0.0f);
    ++mesh.staticRevision;
    if (ops.empty() || faces == 0) return;
    // The class at a surface point is the last operation covering it. Each vertex owns the third
    // of its faces nearest to it (as sampleClassAreas counts it); the area of that cell in each
    // "at least k samples" set is measured with 25 points per face.
    std::vector<std::vector<uint8_t>> filled(ops.size());
    for (size_t k = 0; k < ops.size(); ++k)
        if (ops[k].tool == SamplePaintOp::Tool::Fill)
            filled[k] = fillFaces(mesh, nearestFace(mesh, ops[k].points[0]), static_cast<float>(ops[k].maxAngleDeg),
                                  faceIsland);
    auto classAt = [&](const Eigen::Vector3d& p, size_t f) {
        int c = 0;
        for (size_t k = 0; k < ops.size(); ++k) {
            const SamplePaintOp& op = ops[k];
            bool covered = false;
            if (op.tool == SamplePaintOp::Tool::Fill)
                covered = filled[k][f] != 0;
            else
                for (const Eigen::Vector3d& d : op.points)
                    if ((p - d).squaredNorm() <= op.radius * op.radius) {
                        covered = true;
                        break;
                    }
            if (covered) c = op.samples;
        }
        return c;
    };
    constexpr int kLevel[3] = {1, 4, 8}; // the sets "at least 1×", "at least 4×", "8×"
    std::vector<double> cell(verts, 0.0);
    std::vector<std::array<double, 3>> cover(verts, {0.0, 0.0, 0.0});
    constexpr int n = 5; // n² sub-triangles of equal area, sampled at their centroids
    for (size_t f = 0; f < faces; ++f) {
        const uint32_t idx[3] = {mesh.indices[3 * f], mesh.indices[3 * f + 1], mesh.indices[3 * f + 2]};
        const Eigen::Vector3d a = restOf(mesh, idx[0]), b = restOf(mesh, idx[1]), c = restOf(mesh, idx[2]);
        const double w = 0.5 * (b - a).cross(c - a).norm() / (n * n);
        auto sample = [&](double u, double v) {
            const double bary[3] = {1.0 - u - v, u, v};
            const int cls = classAt(bary[0] * a + bary[1] * b + bary[2] * c, f);
            const double top = std::max({bary[0], bary[1], bary[2]});
            int owners = 0;
            for (double x : bary)
                owners += x >= top - 1e-12;
            for (int k = 0; k < 3; ++k) {
                if (bary[k] < top - 1e-12) continue; // the nearest corner's cell (ties share)
                cell[idx[k]] += w / owners;
                for (int l = 0; l < 3; ++l)
                    if (cls >= kLevel[l]) cover[idx[k]][l] += w / owners;
            }
        };
        for (int i = 0; i < n; ++i)
            for (int j = 0; i + j < n; ++j) {
                sample((i + 1.0 / 3.0) / n, (j + 1.0 / 3.0) / n);
                if (i + j < n - 1) sample((i + 2.0 / 3.0) / n, (j + 2.0 / 3.0) / n);
            }
    }
    // Each set gets the vertices whose cell it covers most, as many as give the discrete area
    // nearest to the set's painted area: the map keeps the painted area to within a cell on any
    // mesh of the surface. Equal coverage (a straight border through a row of cells) is broken
    // by a hash of the index, so the border is dithered rather than cut at one end.
    auto spread = [](uint32_t v) {
        uint32_t h = v * 2654435761u;
        return h ^ (h >> 15);
    };
    std::vector<uint32_t> order;
    for (int l = 0; l < 3; ++l) {
        double target = 0;
        order.clear();
        for (uint32_t v = 0; v < verts; ++v)
            if (cover[v][l] > 0 && cell[v] > 0) {
                target += cover[v][l];
                order.push_back(v);
            }
        std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
            const double fx = cover[x][l] / cell[x], fy = cover[y][l] / cell[y];
            return fx != fy ? fx > fy : spread(x) != spread(y) ? spread(x) < spread(y) : x < y;
        });
        double acc = 0;
        size_t take = 0;
        for (size_t i = 0; i < order.size(); ++i) {
            if (std::abs(acc + cell[order[i]] - target) > std::abs(acc - target)) break;
            acc += cell[order[i]];
            take = i + 1;
        }
        for (size_t i = 0; i < take; ++i)
            mesh.sampleMap[order[i]] = static_cast<float>(kLevel[l]);
    }
}

std::vector<uint8_t> nodeSampleClasses(const RenderMesh& bodySurface, size_t nodeCount) {
    std::vector<uint8_t> out(nodeCount, 0);
    for (size_t v = 0; v < bodySurface.vertexCount() && v < bodySurface.sourceVertex.size(); ++v) {
        const int32_t n = bodySurface.sourceVertex[v];
        if (n >= 0 && size_t(n) < nodeCount && v < bodySurface.sampleMap.size())
            out[size_t(n)] = static_cast<uint8_t>(std::lround(bodySurface.sampleMap[v]));
    }
    return out;
}

void applyNodeSampleClasses(SceneView& view, size_t body, const std::vector<uint8_t>& nodeClasses,
                            const std::vector<size_t>& surfacesOnBody, float tolerance) {
    std::vector<RenderMesh>& meshes = view.meshes();
    const RenderMesh* bodyMesh = nullptr;
    for (RenderMesh& m : meshes) {
        // The cut surface's slots change with the cut: it keeps the default sampling.
        if (m.source != RenderMesh::Source::Body || m.sourceIndex != body || m.cutSurface) continue;
        m.sampleMap.assign(m.vertexCount(), 0.0f);
        for (size_t v = 0; v < m.vertexCount(); ++v) {
            const int32_t n = v < m.sourceVertex.size() ? m.sourceVertex[v] : -1;
            if (n < 0 || size_t(n) >= nodeClasses.size())
                throw std::invalid_argument("render::applyNodeSampleClasses(): mesh " + m.name + ": vertex " +
                                            std::to_string(v) + " is node " + std::to_string(n) + ", the map has " +
                                            std::to_string(nodeClasses.size()) + " nodes");
            if (!isSampleClass(nodeClasses[size_t(n)]))
                throw std::invalid_argument("render::applyNodeSampleClasses(): node " + std::to_string(n) + ": " +
                                            className(nodeClasses[size_t(n)]));
            m.sampleMap[v] = float(nodeClasses[size_t(n)]);
        }
        ++m.staticRevision;
        bodyMesh = &m;
    }
    if (!bodyMesh) return;
    const float tol2 = tolerance * tolerance;
    for (RenderMesh& m : meshes) {
        if (m.source != RenderMesh::Source::Surface ||
            std::find(surfacesOnBody.begin(), surfacesOnBody.end(), m.sourceIndex) == surfacesOnBody.end())
            continue;
        m.sampleMap.assign(m.vertexCount(), 0.0f);
        for (size_t v = 0; v < m.vertexCount(); ++v) {
            const Eigen::Map<const Eigen::Vector3f> p(&m.rest[3 * v]);
            float best = tol2;
            for (size_t u = 0; u < bodyMesh->vertexCount(); ++u) {
                const float d = (Eigen::Map<const Eigen::Vector3f>(&bodyMesh->rest[3 * u]) - p).squaredNorm();
                if (d <= best) best = d, m.sampleMap[v] = bodyMesh->sampleMap[u];
            }
        }
        ++m.staticRevision;
    }
}

void applyBodySampleMap(SceneView& view, size_t body, const std::string& bodyName,
                        const std::vector<uint8_t>& nodeClasses, const std::vector<sim::SurfaceDesc>& surfaces) {
    std::vector<size_t> layers;
    double tolerance = 1e-6;
    for (size_t s = 0; s < surfaces.size(); ++s)
        if (surfaces[s].attachTo == bodyName) {
            layers.push_back(s);
            tolerance = std::max(tolerance, surfaces[s].attachDistance);
        }
    applyNodeSampleClasses(view, body, nodeClasses, layers, static_cast<float>(tolerance));
}

std::vector<uint8_t> parseSampleMap(std::string_view text, const std::string& origin,
                                    std::optional<size_t> expectedNodes) {
    sim::detail::LineReader in(text, origin);
    std::vector<uint8_t> classes;
    sim::detail::readNodeValues(in, "vsamples", expectedNodes, "class",
                                [&](std::string_view tok, size_t, const std::string& what) {
                                    const int c = in.number<int>(tok, what);
                                    if (!isSampleClass(c))
                                        in.fail(what + " is " + std::string(tok) + " (must be 0, 1, 4 or 8)");
                                    classes.push_back(static_cast<uint8_t>(c));
                                });
    return classes;
}

std::string formatSampleMap(const std::vector<uint8_t>& classes) {
    if (classes.empty()) throw std::invalid_argument("render::formatSampleMap(): no classes (need at least one node)");
    std::string out = "vsamples 1\nnodes " + std::to_string(classes.size()) + "\n";
    out.reserve(out.size() + 2 * classes.size());
    for (size_t i = 0; i < classes.size(); ++i) {
        if (!isSampleClass(classes[i]))
            throw std::invalid_argument("render::formatSampleMap(): class of node " + std::to_string(i) + " is " +
                                        std::to_string(classes[i]) + " (must be 0, 1, 4 or 8)");
        out += std::to_string(classes[i]);
        out += '\n';
    }
    return out;
}

} // namespace viscera::render
