#pragma once
/// Opening and verifying a .vcase case package (see packaging/vcase-spec.md).
///
/// CasePackage::open() checks, in this order, and throws viscera::InputError on the first rule
/// broken, with a one-line message naming the package, the entry or field, and the rule:
///   (a) the file exists, is readable, and is at most Limits::maxPackageBytes;
///   (b) it is a zip archive ("not a valid zip archive (truncated or corrupt)") with at most
///       Limits::maxEntries entries;
///   (c) entry names follow entryNameProblem() (no '..', no absolute path, no backslash...);
///       entries are regular files (no symbolic links or devices); no name repeats, even
///       ignoring letter case; directory entries only as parents of packaged files;
///   (d) entries are stored or deflated, not encrypted; the declared uncompressed sizes respect
///       maxEntryBytes, maxTotalBytes and maxCompressionRatio;
///   (e) manifest.json is present, at most maxManifestBytes, valid JSON, and schema-valid
///       (Manifest::parse); signature.json, when present, is at most kMaxSignatureBytes and
///       well formed (PackageSignature::parse); these two are the only entries inflated before
///       the caller's admission check (vcase::checkProvenance: signature, trust, expiry,
///       rollback), so an unsigned or untrusted package never costs its payload;
///   (f) every listed file is present with the listed size and sha256; no file but manifest.json
///       and signature.json is unlisted;
///   (g) the schemaVersion and minPlayerVersion suit this player (checkPlayerCompatibility; the
///       manifest's alone, so it runs right after (e), before the admission);
///   (h) every listed file ending in ".vtet" parses with sim::parseVtet (origin
///       "<package>:<entry>").
/// Example: "case.vcase: meshes/a.vtet: sha256 mismatch (manifest says 3a.., file has 9f..)".
#include "case/limits.hpp"
#include "case/manifest.hpp"
#include "case/signing.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace viscera::vcase {

namespace detail {
struct VerifiedPackage;
}

/// What is known of a package when its admission is decided: its directory passed (a) to (d), and
/// manifest.json and signature.json (e) were read; nothing else was inflated. Views into the
/// package being opened, valid during the admission call.
struct PackageHead {
    const std::string& name; ///< the package as named in messages
    const Manifest& manifest;
    const std::string& manifestText; ///< the exact bytes a signature covers
    const std::optional<PackageSignature>& signature;
    const std::string& sha256; ///< of the whole package file
    uint64_t bytes;
};

/// Called once the head is read and before any other entry is inflated; throws
/// viscera::InputError to refuse the package (open() then throws it).
using Admission = std::function<void(const PackageHead&)>;

/// A verified package, held in memory. Non-copyable; open() returns a unique_ptr.
/// Memory: the uncompressed bytes of every listed file (at most Limits::maxTotalBytes); the
/// archive itself is released once verified.
class CasePackage {
public:
    /// Reads and verifies the package at `path`; `admit` (when set) decides after (e) whether the
    /// rest is read at all. Cost: one read of the file and a SHA-256 pass over it; after
    /// admission, one decompression and one SHA-256 pass over every entry, one parse of every
    /// .vtet. Throws viscera::InputError.
    static std::unique_ptr<CasePackage> open(const std::filesystem::path& path, const Limits& limits = {},
                                             const Admission& admit = {});
    /// The same checks on a package already in memory (only (a)'s size rule applies); `name`
    /// stands for the file in messages. `bytes` is not retained.
    static std::unique_ptr<CasePackage> fromBytes(std::string_view bytes, std::string name, const Limits& limits = {},
                                                  const Admission& admit = {});

    ~CasePackage();
    CasePackage(const CasePackage&) = delete;
    CasePackage& operator=(const CasePackage&) = delete;

    /// The package as named in messages (the path given to open()).
    const std::string& name() const { return m_name; }
    const Manifest& manifest() const { return m_manifest; }
    /// True when `path` is listed in the manifest.
    bool contains(std::string_view path) const;
    /// The verified bytes of listed file `path`; the view lives as long as the package. O(log n).
    /// Throws viscera::InputError ("case.vcase: scene/x.json: not listed in manifest.json") for a
    /// path that is not listed (manifest.json itself included: use manifest()).
    std::string_view read(std::string_view path) const;

    /// The exact bytes of manifest.json (what a signature covers).
    const std::string& manifestText() const { return m_manifestText; }
    /// signature.json, well formed, when the package has one (not yet checked against any key:
    /// vcase::checkProvenance does that).
    const std::optional<PackageSignature>& signature() const { return m_signature; }
    /// SHA-256 (64 lowercase hex) and size of the whole package file: which bytes were run.
    const std::string& sha256() const { return m_sha256; }
    uint64_t bytes() const { return m_bytes; }
    /// The package's head, as its admission saw it (views into this package).
    PackageHead head() const;

private:
    CasePackage() = default;
    static std::unique_ptr<CasePackage> make(std::string name, detail::VerifiedPackage&& v);

    std::string m_name;
    Manifest m_manifest;
    std::string m_manifestText;
    std::optional<PackageSignature> m_signature;
    std::string m_sha256;
    uint64_t m_bytes = 0;
    std::map<std::string, std::string, std::less<>> m_files;
};

/// Checks (a) to (e) of the package at `path` and hands its head to `admit`; no entry but
/// manifest.json and signature.json is inflated (what the launcher lists cases by). Cost: one read
/// of the file and one SHA-256 pass over it. Throws viscera::InputError.
void readPackageHead(const std::filesystem::path& path, const Admission& admit, const Limits& limits = {});
/// The same on a package already in memory (`name` stands for the file in messages): a caller that
/// goes on to CasePackage::fromBytes() on the same bytes checks exactly what it admitted.
void readPackageHead(std::string_view bytes, const std::string& name, const Admission& admit,
                     const Limits& limits = {});

/// Runs every check of CasePackage::open() with no admission and returns the manifest: for a
/// package one made oneself (the studio's tests and tools), never for one to be trusted; for tools that only need a
/// verdict. Same cost as open(); the file contents are released before returning.
Manifest verify(const std::filesystem::path& path, const Limits& limits = {});

} // namespace viscera::vcase
