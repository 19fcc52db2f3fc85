// The CHF queries agree with brute-force adjacency on an unstructured CGAL Mesh_3 mesh.
#include "bake/tetrahedralize.hpp"
#include "sim/mesh/chf_reference.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

using namespace viscera;

TEST(ChfOnCgalMesh, MatchesBruteForce) {
    bake::MeshingParams p;
    p.facetSize = 0.012;
    p.facetDistance = 0.002;
    p.cellSize = 0.012;
    p.seed = 3;
    auto r =
        bake::tetrahedralize(sim::makeEllipsoidSurface(sim::Vec3::Zero(), sim::Vec3(0.07, 0.045, 0.03), 40, 20), p);
    ASSERT_GT(r.mesh->tetCount(), 500u);
    EXPECT_TRUE(r.mesh->quality().inverted.empty());
    sim::testing::expectChfMatchesBruteForce(*r.mesh, 400, 9);
}
