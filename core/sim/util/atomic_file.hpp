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

namespace viscera {

void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes);

/// Default size cap of readFile(): 256 MiB.
inline constexpr std::uintmax_t kReadFileMaxBytes = std::uintmax_t{256} << 20;

/// Reads a whole file of at most `maxBytes` bytes (the one whole-file reader of the tree). Throws
/// viscera::InputError, one line naming the path and the rule: "<path>: cannot open for reading
/// (file not found)" (or "(is a directory, not a file)", "(Permission denied)", ...),
/// "<path>: file is 300000000 bytes, larger than the limit of 268435456 bytes" followed by
/// " (<limitName>)" when `limitName` names the setting behind maxBytes, "<path>: read failed
/// (...)". A FIFO or device is read to its end, up to the same cap.
std::string readFile(const std::filesystem::path& path, std::uintmax_t maxBytes = kReadFileMaxBytes,
                     std::string_view limitName = {});

} // namespace viscera
