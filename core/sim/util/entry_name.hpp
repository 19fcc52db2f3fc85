#pragma once
/// Rules for the paths of files inside a .vcase package (zip entry names, manifest paths, the
/// file references of a scene or project): one rule for every reader.
///
/// A path is one or more components separated by '/', at most kMaxEntryNameBytes bytes, using
/// only the portable characters A-Z a-z 0-9 '.' '_' '-'. It must not be absolute (leading '/',
/// a drive letter "C:"), contain a backslash, or have an empty, "." or ".." component. The rules
/// are checked in that order so that each name gets the most specific message.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace viscera::sim {

inline constexpr size_t kMaxEntryNameBytes = 255;

/// The rule `path` breaks, worded for a message ("entry name escapes the package ('..'
/// component)", "absolute entry path"), or nullopt when the path is acceptable. O(length).
std::optional<std::string> entryNameProblem(std::string_view path);

/// `name` made safe for a one-line message: bytes outside printable ASCII become \xNN and the
/// result is cut after kMaxEntryNameBytes bytes. Names from a hostile archive go through this.
std::string displayName(std::string_view name);

/// True when `file` (symbolic links resolved, as far as it exists) lies in `folder` or below it:
/// the rule that keeps a project's references, and an import's, inside the folder the user gave.
bool insideFolder(const std::filesystem::path& folder, const std::filesystem::path& file);

} // namespace viscera::sim
