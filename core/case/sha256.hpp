#pragma once
/// SHA-256 digests for package integrity (OpenSSL EVP underneath; no OpenSSL type is exposed).
#include <string>
#include <string_view>

namespace viscera::vcase {

/// The SHA-256 of `bytes` as 64 lowercase hexadecimal characters. O(size), on the order of
/// 1 GB/s. Throws std::runtime_error only if OpenSSL itself fails.
std::string sha256Hex(std::string_view bytes);

/// `bytes` as lowercase hexadecimal, two characters a byte (digests, keys, signatures).
std::string hexText(std::string_view bytes);

/// True for exactly 64 characters in [0-9a-f] (the manifest's sha256 form).
bool isSha256Hex(std::string_view text);

} // namespace viscera::vcase
