#pragma once
/// Whole-file input and output.
///
/// Atomic file output: the data goes to a temporary file in the destination folder, is fsync'ed,
/// then renamed over the destination and the folder is fsync'ed. A crash leaves either the old
/// file or the new one, never a torn one. Throws viscera::InputError naming the path on failure.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace viscera {

/// The temporary file is "<folder>/.<name>.<pid>.tmpXXXXXX"; temporaries of the same destination
/// left by a writer that no longer runs (killed mid-write) are removed first. `mode`: the file's
/// permissions (0600 for a secret: it is never readable by others, not even as the temporary).
void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes, unsigned mode = 0644);

/// Refuses, before any work, an output that is one of the inputs (the same file, through links
/// or not): throws viscera::InputError "<output>: cannot write <what> over the input '<input>'".
/// Paths that do not exist yet are compared after resolving the links of their folders.
void requireNotAnInput(const std::filesystem::path& output, std::string_view what,
                       const std::vector<std::filesystem::path>& inputs);

/// Checks, before long work, that writeFileAtomic(path, ...) will be able to write `path`: the
/// path is not a folder, its folder exists or can be created, and a file can be made there (a
/// probe file is created and removed). Throws viscera::InputError, one line "<path>: cannot
/// write <what> (<reason>)", e.g. "out/r.json: cannot write the report (Permission denied)".
void requireWritableFile(const std::filesystem::path& path, std::string_view what);

/// The same for a folder that will receive files: it is created if needed and must take a new
/// file. Throws viscera::InputError "<dir>: ..." naming the reason.
void requireWritableFolder(const std::filesystem::path& dir);

/// Default size cap of readFile(): 256 MiB.
inline constexpr std::uintmax_t kReadFileMaxBytes = std::uintmax_t{256} << 20;

/// Reads a whole regular file of at most `maxBytes` bytes (the one whole-file reader of the tree).
/// Throws viscera::InputError, one line naming the path and the rule: "<path>: cannot open for
/// reading (file not found)" (or "(is a directory, not a file)", "(Permission denied)", ...),
/// "<path>: is not a regular file (a FIFO)" (or a socket, a device: never opened in a way that
/// blocks), "<path>: file is 300000000 bytes, larger than the limit of 268435456 bytes" followed
/// by " (<limitName>)" when `limitName` names the setting behind maxBytes, "<path>: read failed (...)".
std::string readFile(const std::filesystem::path& path, std::uintmax_t maxBytes = kReadFileMaxBytes,
                     std::string_view limitName = {});

/// Refuses a secret (a key) that users other than its owner could read or write: throws
/// viscera::InputError "<path>: <what> is open to other users (mode 644; chmod 600 it)".
void requirePrivateFile(const std::filesystem::path& path, std::string_view what);

} // namespace viscera
