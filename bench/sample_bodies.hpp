#pragma once
/// Bodies of the XPBD samples for the benches (bench_accuracy --variants, bench_stability_margin):
/// the box bodies built in code as the sample projects build them, and .vtet meshes (e.g. the CGAL
/// meshes of organ-blob and liver, unpacked from their exported cases).
#include "sim/material/material.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_mesh.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::bench {

struct SampleBody {
    std::string name;
    std::unique_ptr<sim::TetMesh> mesh;
    std::vector<int32_t> fixed; ///< node indices
    sim::Material material;     ///< stable Neo-Hookean
    double extent = 0;          ///< m, largest distance of a node from the first (energy scale m g L)
};

/// A box of stable Neo-Hookean tissue fixed at x = min (fixBottom: at z = min).
SampleBody boxBody(std::string name, const sim::BoxSpec& spec, double E, double nu, double density, bool fixBottom);
/// "name:E:nu:density:path" of a .vtet file; the nodes in the lowest 5 % of the height are fixed.
/// Throws std::runtime_error on a bad spec or an unreadable file.
SampleBody vtetBody(const std::string& spec);

/// tissue-slab (4,608 tets, 30 kPa), the rectum's fat pad (36,000 tets, 3 kPa, bottom fixed) and
/// the 30,000-tet bench block (20 kPa), all at ν = 0.45.
std::vector<SampleBody> sampleBoxBodies();

} // namespace viscera::bench
