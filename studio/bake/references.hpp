#pragma once
/// Internal to viscera::bake: the external references of a mesh file and the rule that keeps an
/// import inside the file's folder [issue 16 item 3].
///
/// A mesh bought or downloaded may name other files: an OBJ its material libraries (mtllib), a
/// material library its textures (map_Kd, bump, ...), a glTF or GLB its buffers and images
/// (buffers[i].uri, images[i].uri). Every such reference must be a relative path inside the
/// file's folder: not empty, no URI scheme ("file:", "http:", ...; glTF's embedded "data:" URIs
/// are not references), not absolute ("/x", "\x", "C:x"), no ".." component (after glTF's
/// percent-decoding, so "%2E%2E/x" is ".."), no control character. The references are taken
/// from the bytes before any parser reads them, and the import refuses the file at the first
/// one that breaks the rule, so nothing outside the folder is opened; the importer's file
/// system (import.cpp) then also refuses to open anything outside it, symbolic links resolved.
#include "bake/import.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::bake::detail {

struct MeshReference {
    std::string where; ///< "line 3: mtllib", "buffers[0].uri", "images[2].uri"
    std::string path;  ///< as the file names it (glTF: percent-decoded)
};

/// The rule `path` breaks, worded for a message ("leaves the file's folder ('..' component)"),
/// or nullopt when it is a relative path inside the folder. O(length).
std::optional<std::string> referenceProblem(std::string_view path);

/// The references the bytes of a file in `format` make (lines as assimp reads them: LF, CR, FF
/// and NUL end a line, a final backslash joins the next, at most 10,000 statements): OBJ mtllib statements, glTF/GLB
/// buffer and image URIs that are not data: URIs (the JSON is read with the one strict parser, sim::parseJsonText; a
/// GLB's from its first chunk). STL, PLY and FBX (assimp reads no file beside an FBX) make none. Throws InputError
/// naming the file on JSON it cannot read.
std::vector<MeshReference> meshReferences(const std::string& label, SurfaceFormat format, std::string_view bytes);

/// The texture references of a material library (.mtl): every map_*, bump, disp, decal, refl
/// and norm statement's file name (its options before it are not references). Each material
/// library is read once, however many statements name it.
std::vector<MeshReference> materialReferences(const std::string& label, std::string_view bytes);

/// Throws InputError "<label>: <where> '<path>': <rule>; references must be relative paths inside
/// the file's folder" for the first reference that breaks the rule. For an OBJ, each material
/// library that exists in `folder` as a regular file (at most 64 MiB) is read and its texture
/// references are checked the same way ("<label>: cube.mtl line 4: map_Kd '../x.png': ...").
void checkReferences(const std::string& label, SurfaceFormat format, std::string_view bytes,
                     const std::filesystem::path& folder);

} // namespace viscera::bake::detail
