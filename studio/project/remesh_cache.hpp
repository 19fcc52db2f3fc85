#pragma once
/// The kept remesh of a body [issue 57 item 6]: Make simulation-ready runs the remesh of a remesh
/// block once (in a child process) and Apply keeps its surface in the project folder as
///
///   <project>/cache/remesh-<key>.vremesh        key = remeshKey(block)
///
/// so that Tetrahedralize and export read it instead of remeshing again. The key is the sha256 of
/// everything the surface depends on: every part's bytes and CSG operation, in order, the
/// placement (unit, scale, rotation), the remesh numbers and the UV transfer method. A changed
/// block or a changed part file gives another key, so a stale file is never read (it is left
/// behind; deleting cache/ is always safe). The texture does not enter the key (it is laid on
/// by the UVs at export). The file is binary, exact (doubles as written), atomic; a file that
/// fails its checks is refused with a message naming it, never half-used.
#include "project/project.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace viscera::studio {

/// What export meshes from a remesh block: `hull` the closed surface the tets fill (before the
/// seam cut), `surface` the surface its UVs live on (the cut one; the hull when not cut) and `uv`
/// one per triangle of `surface` (empty: none).
struct RemeshedSurface {
    sim::TriMesh hull, surface;
    std::vector<bake::CornerUv> uv;
};

/// The remesh itself, for those who report on it (viscera-studio remesh): the parts as imported
/// and the remesh's full result.
struct RemeshRun {
    std::vector<bake::RemeshPart> parts;
    bake::RemeshResult result;
};

/// The remesh block's parts, placed and imported with their UVs (when the block transfers them).
/// Throws viscera::InputError naming a part without UVs.
std::vector<bake::RemeshPart> importRemeshParts(const RemeshSource& r);

/// Runs the voxel remesh of `r` and the block's UV transfer (counted by remeshRunCount); `run`,
/// when given, receives the parts and the remesh result. `progress` as bake::voxelRemesh.
RemeshedSurface remeshSurface(const RemeshSource& r, RemeshRun* run = nullptr,
                              const bake::RemeshProgress& progress = {});
/// How many times remeshSurface ran in this process (a test counts the remeshes an export costs).
uint64_t remeshRunCount();

/// 64 lowercase hex characters; reads every part file. Throws viscera::InputError naming a part
/// that cannot be read.
std::string remeshKey(const RemeshSource& r);
/// <projectDir>/cache/remesh-<key>.vremesh
std::filesystem::path keptRemeshFile(const std::filesystem::path& projectDir, const std::string& key);

/// Writes / reads the binary surface file. The reader throws viscera::InputError "<file>: <rule>"
/// (bad magic, truncated, a count or index out of range, a non-finite coordinate).
void writeRemeshedSurface(const std::filesystem::path& file, const RemeshedSurface& s);
RemeshedSurface readRemeshedSurface(const std::filesystem::path& file);

/// The block's surface: the kept one when <projectDir>/cache holds it for remeshKey(r) (`reused`
/// set), else remeshSurface(r). An empty projectDir never reuses.
RemeshedSurface keptOrFreshRemesh(const RemeshSource& r, const std::filesystem::path& projectDir,
                                  bool* reused = nullptr);

} // namespace viscera::studio
