#pragma once
// Shared by the dissection tests and bench/bench_dissection.cpp: a flat fascia sheet and the
// systems built on it.
#include "sim/dissection/dissection.hpp"
#include "sim/material/stable_neo_hookean.hpp"
#include "sim/mesh/generators.hpp"

#include <memory>

namespace viscera::sim::dissection_test {

/// Flat sheet in the plane z = 0, centred on the origin: nx × ny square cells of side size/n,
/// two triangles each (2 nx ny triangles), counter-clockwise seen from +z. Border vertices listed
/// in `border`.
inline TriMesh makeSheet(int nx, int ny, double sizeX, double sizeY, std::vector<int32_t>* border = nullptr) {
    std::vector<Vec3> x;
    std::vector<Tri> t;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
            x.emplace_back(-0.5 * sizeX + sizeX * i / nx, -0.5 * sizeY + sizeY * j / ny, 0.0);
            if (border && (i == 0 || j == 0 || i == nx || j == ny)) border->push_back(int32_t(x.size() - 1));
        }
    auto v = [&](int i, int j) { return int32_t(j * (nx + 1) + i); };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            // Alternate the diagonal so that the sheet has no preferred direction.
            if ((i + j) % 2 == 0) {
                t.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1)});
                t.push_back({v(i, j), v(i + 1, j + 1), v(i, j + 1)});
            } else {
                t.push_back({v(i, j), v(i + 1, j), v(i, j + 1)});
                t.push_back({v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)});
            }
        }
    return TriMesh::fromArrays(std::move(x), std::move(t), "makeSheet");
}

/// The 6,050-triangle fascia of the acceptance test: 55 × 55 cells over 60 mm × 60 mm
/// (cell 1.09 mm), border fixed, no gravity, 10 substeps at 60 Hz.
struct FasciaScene {
    TriMesh sheet;
    std::unique_ptr<XpbdSystem> system;
    std::unique_ptr<Dissection> dissection;
};

inline FasciaScene makeFasciaScene(int threads = 1, TissueDissectionParams tissue = fasciaDissectionDefaults(),
                                   HeatGridSettings grid = {}) {
    FasciaScene s;
    std::vector<int32_t> border;
    s.sheet = makeSheet(55, 55, 0.06, 0.06, &border);
    XpbdSystemDesc d;
    SurfaceBodyDesc f;
    f.name = "fascia";
    f.mesh = &s.sheet;
    f.arealDensity = 0.1;
    f.stretchStiffness = 50.0;
    f.fixedNodes = border;
    d.surfaces.push_back(f);
    XpbdSettings set;
    set.gravity = Vec3::Zero();
    set.threads = threads;
    s.system = XpbdSystem::create(d, set);
    DissectionDesc dd;
    dd.system = s.system.get();
    dd.fascia = &s.sheet;
    dd.surface = 0;
    dd.fasciaTissue = tissue;
    dd.grid = grid;
    s.dissection = Dissection::create(dd);
    return s;
}

/// ~30,000-tet fat block (25 × 20 × 10 cells × 6 tets = 30,000; 50 × 40 × 20 mm), bottom fixed.
struct FatScene {
    std::unique_ptr<TetMesh> mesh;
    std::unique_ptr<XpbdSystem> system;
    std::unique_ptr<Dissection> dissection;
};

inline FatScene makeFatScene(int threads = 1, TissueDissectionParams tissue = fatDissectionDefaults()) {
    FatScene s;
    BoxSpec spec;
    spec.origin = Vec3(-0.025, -0.02, -0.02);
    spec.size = Vec3(0.05, 0.04, 0.02);
    spec.cells = {25, 20, 10};
    s.mesh = makeBoxTetMesh(spec);
    s.mesh->requireLevel(3); // boundary faces for the render mask
    XpbdSystemDesc d;
    TetBodyDesc b;
    b.name = "fat";
    b.mesh = s.mesh.get();
    const double E = 3000, nu = 0.45;
    b.model = std::make_shared<StableNeoHookeanModel>(E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu)));
    b.density = 950;
    for (size_t i = 0; i < s.mesh->vertexCount(); ++i)
        if (s.mesh->positions()[i].z() < -0.02 + 1e-9) b.fixedNodes.push_back(int32_t(i));
    d.tetBodies.push_back(b);
    XpbdSettings set;
    set.threads = threads;
    s.system = XpbdSystem::create(d, set);
    DissectionDesc dd;
    dd.system = s.system.get();
    dd.fat = s.mesh.get();
    dd.tetBody = 0;
    dd.fatTissue = tissue;
    s.dissection = Dissection::create(dd);
    return s;
}

} // namespace viscera::sim::dissection_test
