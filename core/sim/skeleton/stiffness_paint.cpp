#include "sim/skeleton/stiffness_paint.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace viscera::sim {

double poly6Kernel(double v, double h) {
    if (!(std::isfinite(h) && h > 0))
        throw std::invalid_argument("sim::poly6Kernel(): h is " + std::to_string(h) + " (must be finite and > 0)");
    if (!(std::isfinite(v) && v >= 0))
        throw std::invalid_argument("sim::poly6Kernel(): v is " + std::to_string(v) + " (must be finite and >= 0)");
    if (v >= h) return 0.0;
    // h² − v² as (h − v)(h + v): h − v is exact near h (Sterbenz), so the value keeps full relative
    // precision up to the edge of the support instead of cancelling.
    const double d = (h - v) * (h + v);
    const double h3 = h * h * h;
    return 315.0 / (64.0 * std::numbers::pi * h3 * h3 * h3) * (d * d * d);
}

namespace {

[[noreturn]] void failParam(const std::string& origin, const std::string& field, double value, const char* rule) {
    throw std::invalid_argument(origin + ": PaintParams::" + field + " is " + std::to_string(value) + " (" + rule +
                                ")");
}

void validateParams(const PaintParams& p) {
    if (!(std::isfinite(p.minWeight) && p.minWeight > 0))
        failParam(p.origin, "minWeight", p.minWeight, "must be finite and > 0: XPBD divides compliance by weights");
    if (!(std::isfinite(p.maxWeight) && p.maxWeight >= p.minWeight))
        failParam(p.origin, "maxWeight", p.maxWeight, "must be finite and >= minWeight");
    if (!(std::isfinite(p.baseWeight) && p.baseWeight >= p.minWeight && p.baseWeight <= p.maxWeight))
        failParam(p.origin, "baseWeight", p.baseWeight, "must be finite and in [minWeight, maxWeight]");
}

/// The kernel factor k of a node at distance v from the centre (BrushMode).
double kernelFactor(const BrushStroke& s, double v) {
    if (s.scale == BrushScale::Peak) return poly6Kernel(v, s.radius) / poly6Kernel(0.0, s.radius);
    return poly6Kernel(v, s.radius);
}

/// Added weight (Add, Subtract) or blend factor (Mix, Smooth) at distance v.
double strokeIncrement(const BrushStroke& s, double v) {
    const double k = s.amplitude * kernelFactor(s, v);
    return s.mode == BrushMode::Subtract ? -k : k;
}

bool blends(BrushMode m) {
    return m == BrushMode::Mix || m == BrushMode::Smooth;
}

} // namespace

void validateStroke(const BrushStroke& s, size_t index, const std::string& origin) {
    const std::string p = origin + ": stroke " + std::to_string(index) + ": ";
    if (!s.center.allFinite()) throw std::invalid_argument(p + "center has a non-finite coordinate");
    if (!(s.radius >= kMinBrushRadius && s.radius <= kMaxBrushRadius))
        throw std::invalid_argument(p + "radius is " + std::to_string(s.radius) + " m (must be in [1e-6, 1e3] m)");
    if (!std::isfinite(s.amplitude))
        throw std::invalid_argument(p + "amplitude is " + std::to_string(s.amplitude) + " (must be finite)");
    if (s.scale != BrushScale::Peak && s.scale != BrushScale::Kernel)
        throw std::invalid_argument(p + "scale is not a BrushScale value");
    if (s.mode != BrushMode::Add && s.mode != BrushMode::Subtract && !blends(s.mode))
        throw std::invalid_argument(p + "mode is not a BrushMode value");
    if (blends(s.mode) && s.amplitude < 0)
        throw std::invalid_argument(p + "amplitude is " + std::to_string(s.amplitude) +
                                    " (a mix or smooth strength must be >= 0)");
    if (s.mode == BrushMode::Mix && !(std::isfinite(s.target) && s.target > 0))
        throw std::invalid_argument(p + "target is " + std::to_string(s.target) + " (must be finite and > 0)");
    // The peak increment must be finite too (BrushScale::Kernel multiplies by up to 315/(64π h³)).
    if (!std::isfinite(strokeIncrement(s, 0.0)))
        throw std::invalid_argument(p + "amplitude × kernel at the centre is not finite");
}

namespace {

/// The stroke on the nodes of `selected` (sorted, unique): the mode's change, then the clamp.
/// Commits only when every value is finite.
void applyToSelection(const std::vector<Vec3>& positions, const std::vector<int32_t>& selected,
                      const BrushStroke& stroke, const PaintParams& params, std::vector<double>& weights,
                      StiffnessPaintReport* report, const NodeNeighbours* neighbours, size_t index) {
    std::vector<double> next(selected.size());
    size_t changed = 0, low = 0, high = 0;
    for (size_t k = 0; k < selected.size(); ++k) {
        const int32_t i = selected[k];
        const double inc = strokeIncrement(stroke, (positions[i] - stroke.center).norm());
        double w = weights[i];
        if (stroke.mode == BrushMode::Mix) {
            w += std::min(1.0, inc) * (stroke.target - w);
        } else if (stroke.mode == BrushMode::Smooth) {
            // Jacobi: the neighbours' weights before this stroke (weights is written after the loop)
            const int32_t b = neighbours->start[i], e = neighbours->start[i + 1];
            if (e > b) {
                double sum = 0;
                for (int32_t q = b; q < e; ++q)
                    sum += weights[neighbours->members[q]];
                w += std::min(1.0, inc) * (sum / (e - b) - w);
            }
        } else {
            w += inc;
        }
        if (!std::isfinite(w))
            throw std::invalid_argument(params.origin + ": stroke " + std::to_string(index) + ": weight of node " +
                                        std::to_string(i) + " is not finite");
        if (inc != 0.0) ++changed;
        if (w < params.minWeight) {
            w = params.minWeight;
            ++low;
        } else if (w > params.maxWeight) {
            w = params.maxWeight;
            ++high;
        }
        next[k] = w;
    }
    for (size_t k = 0; k < selected.size(); ++k)
        weights[selected[k]] = next[k];
    if (report) {
        report->strokeSelected.push_back(selected.size());
        report->strokeChanged.push_back(changed);
        report->clampedLow += low;
        report->clampedHigh += high;
    }
}

/// The checks both kinds of stroke share; returns the stroke's index for messages.
size_t checkStroke(size_t n, const BrushStroke& stroke, const PaintParams& params, const std::vector<double>& weights,
                   const StiffnessPaintReport* report, const NodeNeighbours* neighbours) {
    validateParams(params);
    const size_t index = report ? report->strokeSelected.size() : 0;
    validateStroke(stroke, index, params.origin);
    if (weights.size() != n)
        throw std::invalid_argument(params.origin + ": stroke " + std::to_string(index) + ": " +
                                    std::to_string(weights.size()) + " weights for " + std::to_string(n) +
                                    " positions: sizes must agree");
    if (stroke.mode == BrushMode::Smooth && (!neighbours || neighbours->nodeCount() != n))
        throw std::invalid_argument(params.origin + ": stroke " + std::to_string(index) +
                                    ": smoothing needs the neighbours of the mesh's " + std::to_string(n) + " nodes");
    return index;
}

/// Neighbours from elements of N nodes each: every pair of nodes of an element.
template <class Elements> NodeNeighbours neighboursOf(const Elements& elements, size_t n) {
    std::vector<std::pair<int32_t, int32_t>> pairs;
    for (const auto& t : elements)
        for (size_t a = 0; a < t.size(); ++a)
            for (size_t b = 0; b < t.size(); ++b)
                if (a != b) pairs.emplace_back(t[a], t[b]);
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    NodeNeighbours nb;
    nb.start.assign(n + 1, 0);
    for (const auto& [a, b] : pairs)
        ++nb.start[a + 1];
    for (size_t i = 0; i < n; ++i)
        nb.start[i + 1] += nb.start[i];
    nb.members.reserve(pairs.size());
    for (const auto& pr : pairs)
        nb.members.push_back(pr.second); // sorted by first: node order
    return nb;
}

} // namespace

void applyBrushStroke(const std::vector<Vec3>& positions, const Skeleton& skeleton, const SkeletonNodeMap& map,
                      const BrushStroke& stroke, const PaintParams& params, std::vector<double>& weights,
                      StiffnessPaintReport* report, const NodeNeighbours* neighbours) {
    const size_t index = checkStroke(positions.size(), stroke, params, weights, report, neighbours);
    if (map.meshNodeCount != positions.size() || map.skeletonNodeCount() != skeleton.nodes.size())
        throw std::invalid_argument(params.origin + ": stroke " + std::to_string(index) + ": a map of " +
                                    std::to_string(map.meshNodeCount) + " nodes for " +
                                    std::to_string(positions.size()) +
                                    " positions: sizes must agree (and the map must come from this skeleton)");
    // Selection through the skeleton: skeleton nodes strictly inside the brush select their Π_j.
    std::vector<int32_t> selected;
    for (size_t j = 0; j < skeleton.nodes.size(); ++j)
        if ((skeleton.nodes[j] - stroke.center).norm() < stroke.radius)
            selected.insert(selected.end(), map.members.begin() + map.start[j], map.members.begin() + map.start[j + 1]);
    if (stroke.reach == BrushReach::Sphere) // and the nodes the brush touches itself
        for (size_t i = 0; i < positions.size(); ++i)
            if ((positions[i] - stroke.center).norm() < stroke.radius) selected.push_back(static_cast<int32_t>(i));
    std::sort(selected.begin(), selected.end());
    selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
    applyToSelection(positions, selected, stroke, params, weights, report, neighbours, index);
}

void applySurfaceBrushStroke(const std::vector<Vec3>& positions, const BrushStroke& stroke, const PaintParams& params,
                             std::vector<double>& weights, StiffnessPaintReport* report,
                             const NodeNeighbours* neighbours) {
    const size_t index = checkStroke(positions.size(), stroke, params, weights, report, neighbours);
    std::vector<int32_t> selected; // polygon paint: the vertices strictly inside the brush
    for (size_t i = 0; i < positions.size(); ++i)
        if ((positions[i] - stroke.center).norm() < stroke.radius) selected.push_back(static_cast<int32_t>(i));
    applyToSelection(positions, selected, stroke, params, weights, report, neighbours, index);
}

NodeNeighbours nodeNeighbours(const TriMesh& mesh) {
    return neighboursOf(mesh.triangles(), mesh.vertexCount());
}

std::vector<double> bakeSurfacePaint(const TriMesh& mesh, const std::vector<BrushStroke>& strokes,
                                     const PaintParams& params, StiffnessPaintReport* report) {
    validateParams(params);
    for (size_t k = 0; k < strokes.size(); ++k)
        validateStroke(strokes[k], k, params.origin);
    std::vector<double> w(mesh.vertexCount(), params.baseWeight);
    const bool smooth =
        std::any_of(strokes.begin(), strokes.end(), [](const BrushStroke& s) { return s.mode == BrushMode::Smooth; });
    const NodeNeighbours nb = smooth ? nodeNeighbours(mesh) : NodeNeighbours{};
    StiffnessPaintReport local;
    StiffnessPaintReport& r = report ? *report : local;
    for (const BrushStroke& s : strokes)
        applySurfaceBrushStroke(mesh.positions(), s, params, w, &r, smooth ? &nb : nullptr);
    if (!w.empty()) {
        const auto [lo, hi] = std::minmax_element(w.begin(), w.end());
        r.minWeight = *lo;
        r.maxWeight = *hi;
    }
    return w;
}

NodeNeighbours nodeNeighbours(const TetMesh& mesh) {
    return neighboursOf(mesh.tets(), mesh.vertexCount());
}

StiffnessPaintResult bakeStiffnessPaint(const TetMesh& mesh, const Skeleton& skeleton,
                                        const std::vector<BrushStroke>& strokes, const PaintParams& params) {
    validateParams(params);
    for (size_t k = 0; k < strokes.size(); ++k)
        validateStroke(strokes[k], k, params.origin);
    StiffnessPaintResult r;
    r.map = mapNodesToSkeleton(mesh.positions(), skeleton, params.origin);
    r.weights.assign(mesh.vertexCount(), params.baseWeight);
    const bool smooth =
        std::any_of(strokes.begin(), strokes.end(), [](const BrushStroke& s) { return s.mode == BrushMode::Smooth; });
    const NodeNeighbours nb = smooth ? nodeNeighbours(mesh) : NodeNeighbours{};
    for (const BrushStroke& s : strokes)
        applyBrushStroke(mesh.positions(), skeleton, r.map, s, params, r.weights, &r.report, smooth ? &nb : nullptr);
    r.report.fallbackNodes = r.map.fallbackNodes.size();
    const auto [lo, hi] = std::minmax_element(r.weights.begin(), r.weights.end());
    r.report.minWeight = *lo;
    r.report.maxWeight = *hi;
    return r;
}

} // namespace viscera::sim
