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

/// The hepatocystic triangle's anatomy made by code [issue 57 item 4], as bought render anatomy
/// arrives: separate overlapping parts, some open, each with UVs in one atlas (the layout of
/// hepatocysticAtlas in project/sample_hepatocystic.hpp). Metres, z up (the patient's anterior).
///   "liver"             the right lobe's underside: a flattened ellipsoid 180 × 130 × 60 mm
///                       whose top (the bare area) is missing: open; one island
///   "gallbladder"       a pear 32 × 84 mm in its bed, its top 13 mm inside the liver, the fundus
///                       at +y, tapering to the neck at −y; two islands
///   "cystic_duct"       an open tube (radius 2.5 mm) from the neck to the common bile duct
///   "common_bile_duct"  an open tube (radius 4 mm) past the cystic duct's end, overlapping it
///   "cystic_artery"     a closed capped tube (radius 1.5 mm) whose end lies inside the neck;
///                       three islands (side and caps)
/// `slices` sets the tessellation. Deterministic.
std::vector<RemeshPart> hepatocysticAnatomy(int slices = 64);

} // namespace viscera::bake
