#pragma once
/// A kidney-like anatomy made by code [issue 16 item 7], the way render anatomy arrives: several
/// overlapping parts, one self-intersecting, one with a small hole, one open tube. Sizes in metres
/// (a kidney about 11 × 6 × 4 cm). The input of the remesh sample, test and bench.
#include "bake/remesh.hpp"

#include <vector>

namespace viscera::bake {

/// The parts, all joined by union:
///   "cortex"  a bean: an ellipsoid (radii 30 × 55 × 20 mm, long axis y) whose medial (+x) side is
///             pushed in by a Gaussian dent 70 mm deep, so the dent passes through the far side
///             (self-intersecting), with one triangle near the upper pole missing (a hole of about
///             the triangle's size);
///   "pelvis"  an ellipsoid in the hilum, overlapping the cortex and the dent;
///   "ureter"  an open tube (no end caps) from the pelvis downwards, radius 4 mm;
///   "artery"  a closed capped tube into the hilum, radius 3 mm, overlapping the pelvis.
/// Each part carries per-corner UVs in one texture atlas: the cortex a latitude–longitude island
/// with its seam inside it (the lateral meridian), the pelvis two islands (front and back), the
/// ureter one (a seam along it), the artery three (side and both caps).
/// `slices` sets the tessellation (the cortex has slices × slices/2 quads). Deterministic.
std::vector<RemeshPart> kidneyAnatomy(int slices = 96);

} // namespace viscera::bake
