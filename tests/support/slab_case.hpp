#pragma once
// A small cantilever case for the player's end-to-end tests: an 8 × 2 × 2 cm box of 20 kPa tissue
// fixed at x = 0, 50 substeps, signed with the build's sample publisher key unless told otherwise.
#include "case/manifest.hpp"
#include "case/zip_craft.hpp"
#include "sim/mesh/tri_mesh.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace viscera::test {

struct SlabCase {
    std::string caseId = "slab-test";
    std::string caseVersion = "1.0.0";
    std::vector<std::string> features{"gravity", "xpbd"};
    sim::Vec3 gravity{0, 0, -9.81};
    std::string render;                          ///< the scene's "render" block, JSON text (empty: none)
    std::optional<std::string> expires;          ///< manifest "expires"
    std::string signingKey = VISCERA_SAMPLE_KEY; ///< PEM private key; empty: unsigned
};

/// The case's files (meshes/slab.vtet, scene.json) and manifest header (files[] empty).
std::vector<vcase::test::RawEntry> slabCaseFiles(const SlabCase& slab);
vcase::Manifest slabCaseHeader(const SlabCase& slab);
/// Writes the package with vcase::CaseWriter (signed with slab.signingKey when not empty).
std::filesystem::path writeSlabCase(const std::filesystem::path& file, const SlabCase& slab);

} // namespace viscera::test
