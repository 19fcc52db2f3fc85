// signature.json of a case package (vcase::PackageSignature::parse, core/case/signing.hpp). What it
// accepts must format and parse back to the same fields; its key and signature then go through
// keyId() and the Ed25519 check over a manifest (any 32 and 64 bytes: a false answer, never a
// crash), as the player's trust check does.
#include "case/signing.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using viscera::vcase::PackageSignature;
    PackageSignature s;
    try {
        s = PackageSignature::parse(std::string_view(reinterpret_cast<const char*>(data), size), "signature.json");
    } catch (const viscera::InputError&) {
        return 0;
    }
    if (s.publicKey.size() != viscera::vcase::kPublicKeyBytes || s.signature.size() != viscera::vcase::kSignatureBytes)
        std::abort();
    const PackageSignature back = PackageSignature::parse(s.toJsonText(), "signature.json (formatted)");
    if (back.signer != s.signer || back.publicKey != s.publicKey || back.signature != s.signature) std::abort();
    (void)viscera::vcase::keyId(s.publicKey);
    (void)viscera::vcase::verifySignature(s.publicKey, viscera::vcase::signedMessage("{\"schemaVersion\": 1}\n"),
                                          s.signature);
    return 0;
}
