#pragma once
/// Building a .vcase case package (see packaging/vcase-spec.md).
///
///   vcase::Manifest header;                 // every field but files
///   header.caseId = "liver-resection-01"; header.caseVersion = "1.0.0";
///   header.minPlayerVersion = "0.1.0"; header.features = {"xpbd", "gravity"};
///   vcase::CaseWriter writer(header);
///   writer.addFile("meshes/liver.vtet", vtetText);
///   writer.sign(key, "Viscera samples");   // optional: signature.json over manifest.json
///   vcase::Manifest written = writer.write("liver.vcase");
///
/// The package is deterministic: manifest.json first, signature.json (when signed; Ed25519
/// signatures are deterministic) second, then the files sorted by path, deflate
/// level 9, fixed timestamps (1980-01-01 00:00) and modes (0644), so the same header and files
/// give byte-identical packages. Before anything is written the package is verified with the
/// same checks as CasePackage::open(), so a package the player would reject is never produced.
#include "case/limits.hpp"
#include "case/manifest.hpp"
#include "case/signing.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <string_view>

namespace viscera::vcase {

class CaseWriter {
public:
    /// `header` holds every manifest field but files, which must be empty (write() lists the
    /// added files). Throws viscera::InputError ("vcase::CaseWriter: caseId: ...") when a field
    /// breaks the manifest schema.
    explicit CaseWriter(Manifest header);

    /// Adds a file at `path` inside the package. Throws viscera::InputError
    /// ("vcase::CaseWriter::addFile(): ../x: entry name escapes the package ('..' component)")
    /// for a name breaking entryNameProblem(), for "manifest.json" or "signature.json", and for a path already added
    /// (or equal to one ignoring letter case). Keeps a copy of the bytes until the writer dies.
    void addFile(std::string_view path, std::string bytes);

    /// Signs the package with `key` (non-owning: it must outlive build() and write()) under the
    /// display name `signer` (printable, at most kMaxSignerBytes; checked when the package is
    /// verified before it is written).
    void sign(const SigningKey& key, std::string signer);

    size_t fileCount() const { return m_files.size(); }
    const Manifest& header() const { return m_header; }

    /// The manifest write() would package: header plus files[] (sorted by path) with sizes and
    /// SHA-256 digests. O(total bytes).
    Manifest manifest() const;

    /// The package bytes, verified against `limits` (messages name "vcase::CaseWriter::build()").
    /// O(total bytes): one compression, one verification pass. Throws viscera::InputError.
    std::string build(const Limits& limits = {}) const;

    /// Builds and verifies the package (messages name `path`), then writes it with
    /// viscera::writeFileAtomic. Returns the manifest written; `sha256`, when given, receives the
    /// digest of the package's bytes (the verification computed it). Throws viscera::InputError.
    Manifest write(const std::filesystem::path& path, const Limits& limits = {}, std::string* sha256 = nullptr) const;

private:
    std::string buildNamed(const std::string& name, const Limits& limits, Manifest* written, std::string* sha256) const;

    Manifest m_header;
    const SigningKey* m_key = nullptr;
    std::string m_signer;
    std::map<std::string, std::string> m_files;       ///< sorted by path: the package order
    std::map<std::string, std::string> m_foldedPaths; ///< lower-case path -> path as added
};

} // namespace viscera::vcase
