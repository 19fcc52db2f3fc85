#include "case/sha256.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <stdexcept>

namespace viscera::vcase {

std::string sha256Hex(std::string_view bytes) {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1 || length != 32)
        throw std::runtime_error("vcase::sha256Hex(): OpenSSL EVP_Digest failed");
    return hexText(std::string_view(reinterpret_cast<const char*>(digest), length));
}

std::string hexText(std::string_view bytes) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string hex(2 * bytes.size(), '0');
    for (size_t i = 0; i < bytes.size(); ++i) {
        const auto b = static_cast<unsigned char>(bytes[i]);
        hex[2 * i] = kHex[b >> 4];
        hex[2 * i + 1] = kHex[b & 0xf];
    }
    return hex;
}

bool isSha256Hex(std::string_view text) {
    return text.size() == 64 && std::all_of(text.begin(), text.end(),
                                            [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

} // namespace viscera::vcase
