#pragma once
/// Atomic file output: the data goes to a temporary file in the destination folder, is fsync'ed,
/// then renamed over the destination and the folder is fsync'ed. A crash leaves either the old
/// file or the new one, never a torn one. Throws viscera::InputError naming the path on failure.
#include <filesystem>
#include <string>
#include <string_view>

namespace viscera {

void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes);

/// Reads a whole file; throws viscera::InputError naming the path when it cannot be read.
std::string readFile(const std::filesystem::path& path);

} // namespace viscera
