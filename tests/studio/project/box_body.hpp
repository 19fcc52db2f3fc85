#pragma once
// A box body of `size` (m) in `cells`, named "tissue", held at its x = 0 face: what File → New
// once added, built by hand in the tests that need a body.
#include "project/project.hpp"

namespace viscera::test {

inline studio::BodyProject boxBody(const sim::Vec3& size, std::array<int, 3> cells) {
    studio::BodyProject b;
    b.scene.name = "tissue";
    b.scene.material = studio::newBodyMaterial();
    b.mesh.kind = studio::MeshSource::Kind::Box;
    b.mesh.box.origin = sim::Vec3::Zero();
    b.mesh.box.size = size;
    b.mesh.box.cells = cells;
    b.fixedBoxes = {
        std::array<sim::Vec3, 2>{sim::Vec3::Constant(-0.001), sim::Vec3(0.0001, size.y() + 0.001, size.z() + 0.001)}};
    return b;
}

} // namespace viscera::test
