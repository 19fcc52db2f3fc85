#pragma once
/// Whether a file or folder may anchor trust: a publisher key the player trusts, a trust folder,
/// the state folder that guards against rollback. The rule is the one OpenSSH applies to
/// `authorized_keys`: the entry is not a symbolic link and is owned by root or by the user running
/// the player and writable by no one else (a group write bit counts only for the user's private
/// group); every folder the path passes through, up to `/` and through every link it follows, is
/// the same, except that a root-owned folder with the sticky bit (`/tmp`) may be above an anchor:
/// there only an entry's owner can rename or remove it.
#include <filesystem>
#include <string_view>

namespace viscera::vcase {

/// Resolves `path` one component at a time and checks it; returns the resolved path (read that
/// one: no link can be swapped in by anyone but root and the user). Throws viscera::InputError
/// with one line naming `path`, `what` it is ("a trusted publisher key", "a trust folder", "the
/// state folder") and the rule, naming the folder that fails. A path that does not exist passes
/// when the folders it passes through do (the caller reads it, skips it or creates it, and says
/// so). Cost: one lstat per path component and per link followed.
std::filesystem::path requireSafeAnchor(const std::filesystem::path& path, std::string_view what);

} // namespace viscera::vcase
