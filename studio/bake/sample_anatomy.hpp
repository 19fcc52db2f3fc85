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
/// hepatocysticAtlas in project/sample_anatomy_files.hpp). Metres, z up (the patient's anterior).
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

/// The mesorectum and its pelvis made by code [issue 57 item 5], as bought anatomy arrives: separate
/// parts that overlap, some open, each with UVs in one atlas. Metres; x runs along the rectum
/// (proximal −x to distal +x), z up (the patient's posterior, seen from the laparoscope above). The
/// rectum's axis is the line along x through y 10 mm, z −32 mm.
///   "mesorectum"   the fat around the rectum over its upper 190°: a closed shell from x −62 to
///                  +62 mm whose inner face (radius 22.5 mm) lies 2 mm inside the rectal wall and
///                  whose outer face (radius 32 mm, lobulated by up to ±0.9 mm away from its top
///                  40°) is smooth where the surgeon opens it; it thins towards its ends and sides.
///                  Three islands (outer face, inner face, rims)
///   "rectum"       an open tube (no caps) of radius 24.6 mm from x −100 to +110 mm; one island
///   "pelvic_wall"  the pelvic side walls and sacral hollow: an open part of a cylinder of radius
///                  75 mm (about the line along x through y 10 mm, z −25 mm) from 55° to 305° of
///                  +z, deepening towards the sacrum; its triangles face the axis; one island
///   "peritoneum"   the peritoneal reflection closing the pelvis at x +110 mm: a shallow dome of
///                  radius 75 mm facing −x; one island
/// `slices` sets the tessellation. Deterministic.
std::vector<RemeshPart> rectumAnatomy(int slices = 64);

} // namespace viscera::bake
