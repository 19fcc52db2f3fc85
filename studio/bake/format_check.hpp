#pragma once
/// Internal to viscera::bake (not part of the public API): the whitelist of surface formats and
/// the structural checks run on a file's bytes before any third-party parser sees them.
/// Every function throws viscera::InputError with "<file>: <element>: <rule>" on failure.
#include "bake/import.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::bake::detail {

/// Small text and byte helpers of the format checks (ASCII only): blanks are space, tab, CR, LF,
/// FF and VT.
bool isSpace(char c);
char lower(char c);
std::string_view trimLeft(std::string_view s);
std::string_view trim(std::string_view s);
bool startsWithNoCase(std::string_view s, std::string_view prefix);
/// The little-endian uint32 at byte `at` (the caller checks that 4 bytes are there).
uint32_t readU32le(std::string_view b, size_t at);

/// Splits a line on blanks (space, tab, CR, LF, FF, VT); the tokens are views into s.
std::vector<std::string_view> blankSeparatedTokens(std::string_view s);

/// The file's extension, lower case with the dot ("" when it has none).
std::string lowerExtension(const std::filesystem::path& file);

/// Throws "unsupported format '.xyz' (accepted: ...)" when the extension is not in the whitelist.
void checkExtension(const std::string& label, std::string_view extension);

/// Format from the extension, confirmed by the content. Throws on an empty file, an extension
/// outside the whitelist, or content that does not match the extension.
SurfaceFormat sniffFormat(const std::string& label, std::string_view extension, std::string_view bytes);

/// Format-specific structural checks on the raw bytes, done before assimp parses them:
/// OBJ   vertex coordinates parse and are finite; face, texture and normal indices are in range;
///       at least one face with three or more vertices.
/// STL   binary: triangle count > 0 and finite coordinates; ASCII: at least one facet and
///       finite vertex coordinates.
/// PLY   well-formed header ending in end_header; the body holds every declared element
///       (not truncated); finite x, y, z; face indices in range; at least one face.
/// GLB   version 1 or 2, declared length equals the file size, first chunk inside the file.
/// glTF, FBX: no further checks here (assimp's parsers for them are bounds-checked).
void checkStructure(const std::string& label, SurfaceFormat format, std::string_view bytes);

} // namespace viscera::bake::detail
