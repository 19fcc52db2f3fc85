#pragma once
/// Whether a file or folder may anchor trust: a publisher key the player trusts, a trust folder,
/// the state folder that guards against rollback. The rule is the one OpenSSH applies to
/// `authorized_keys`: the entry is not a symbolic link, and it and every folder above it up to `/`
/// is owned by root or by the user running the player and writable by no one else. A folder that
/// others may write but that has the sticky bit and belongs to root (`/tmp`) passes: there only an
/// entry's owner can rename or remove it.
#include <filesystem>
#include <string_view>

namespace viscera::vcase {

/// Throws viscera::InputError with one line naming `path` (or the folder above it that fails),
/// `what` it is ("a trusted publisher key", "a trust folder", "the state folder") and the rule.
/// A path that does not exist passes when the folders above it do (the caller reads it, skips it
/// or creates it, and says so).
/// Cost: one lstat per path component, twice (the path as named and its resolved folder).
void requireSafeAnchor(const std::filesystem::path& path, std::string_view what);

} // namespace viscera::vcase
