#include "uv_report.hpp"

#include "app/uv_preview.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>

using namespace viscera;

namespace {

void figure(std::string_view method, const char* name, double value) {
    std::printf("uv.%.*s.%s %.6g\n", int(method.size()), method.data(), name, value);
}

void printStats(std::string_view method, const bake::UvTransferStats& st, double seconds) {
    figure(method, "triangles", double(st.triangles));
    figure(method, "over_two_islands", double(st.spanningIslands));
    figure(method, "over_a_seam", double(st.seamCrossed));
    figure(method, "flipped", double(st.flipped));
    figure(method, "angle_p50", st.angleP50);
    figure(method, "angle_p95", st.angleP95);
    figure(method, "angle_max", st.angleMax);
    figure(method, "area_p50", st.areaP50);
    figure(method, "area_p95", st.areaP95);
    figure(method, "area_max", st.areaMax);
    figure(method, "over_threshold_pct", 100.0 * st.overThreshold);
    figure(method, "uv_error_mean", st.uvErrorMean);
    figure(method, "uv_error_p95", st.uvErrorP95);
    figure(method, "uv_error_max", st.uvErrorMax);
    figure(method, "seconds", seconds);
}

studio::UvPreviewItem sourceItem(const std::vector<bake::RemeshPart>& parts) {
    studio::UvPreviewItem item;
    item.name = "source";
    std::vector<sim::Vec3> pos;
    std::vector<sim::Tri> tris;
    for (const bake::RemeshPart& part : parts) {
        const auto base = int32_t(pos.size());
        pos.insert(pos.end(), part.surface.positions().begin(), part.surface.positions().end());
        for (const sim::Tri& t : part.surface.triangles())
            tris.push_back({t[0] + base, t[1] + base, t[2] + base});
        item.uv.insert(item.uv.end(), part.uv.begin(), part.uv.end());
    }
    item.mesh = sim::TriMesh::fromArrays(std::move(pos), std::move(tris), "source parts");
    return item;
}

} // namespace

bake::UvTransferMethod parseUvTransferOption(std::string_view name) {
    for (auto m : {bake::UvTransferMethod::SeamCutting, bake::UvTransferMethod::ClosestPoint,
                   bake::UvTransferMethod::IslandLabelled})
        if (name == uvTransferOptionName(m)) return m;
    throw std::invalid_argument("--uv-transfer '" + std::string(name) +
                                "': the methods are seam-cut, closest and island (or --no-uv)");
}

std::string_view uvTransferOptionName(bake::UvTransferMethod method) {
    switch (method) {
    case bake::UvTransferMethod::ClosestPoint:
        return "closest";
    case bake::UvTransferMethod::IslandLabelled:
        return "island";
    case bake::UvTransferMethod::SeamCutting:
        return "seam-cut";
    }
    return "seam-cut";
}

UvChoice reportUvTransfers(const std::vector<bake::RemeshPart>& parts, const bake::RemeshResult& r,
                           bake::UvTransferMethod chosen, const std::optional<std::string>& preview) {
    const bake::UvSource source(parts);
    std::printf("uv.source.triangles %zu\nuv.source.islands %zu\nuv.source.charts %zu\nuv.source.seam_edges %zu\n",
                source.triangleCount(), source.islandCount(), source.chartCount(), source.seamEdgeCount());
    const bake::SeamCutReport& c = r.report.seamCut;
    std::printf("uv.cut.edges_split %zu\nuv.cut.vertices_snapped %zu\nuv.cut.refined %zu\nuv.cut.triangles_split "
                "%zu\nuv.cut.unresolved_pieces %zu\nuv.cut.seam_edges_after_remesh %zu\n",
                c.crossedEdges, c.snappedVertices, c.refinedEdges, c.splitTriangles, c.unresolvedPieces,
                r.report.seamEdges);
    UvChoice choice;
    std::vector<studio::UvPreviewItem> items{sourceItem(parts)};
    for (auto m : {bake::UvTransferMethod::ClosestPoint, bake::UvTransferMethod::IslandLabelled,
                   bake::UvTransferMethod::SeamCutting}) {
        const bool cut = m == bake::UvTransferMethod::SeamCutting;
        const sim::TriMesh& mesh = cut ? r.mesh : r.uncut;
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<bake::CornerUv> uv = cut ? r.uv : bake::transferUv(source, mesh, m);
        const double took =
            cut ? r.report.uvSeconds : std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const bake::UvTransferStats st = bake::measureUvTransfer(source, mesh, uv);
        printStats(uvTransferOptionName(m), st, took);
        choice.stats.emplace_back(std::string(uvTransferOptionName(m)), st);
        if (m != bake::UvTransferMethod::IslandLabelled)
            items.push_back({cut ? "seam cutting" : "closest point", mesh, uv, {}});
        if (cut) // the seam cut's stretch heat map with its seams, beside it
            items.push_back({"seam-cut stretch", mesh, uv, studio::stretchOverlay(mesh, st.faceStretch, r.seamEdges)});
        if (m == chosen) choice.mesh = &mesh, choice.uv = std::move(uv);
    }
    if (preview) {
        studio::writeUvPreview(*preview, items);
        std::printf("wrote %s (left to right: source, closest point, seam cutting, its stretch and seams)\n",
                    preview->c_str());
    }
    return choice;
}
