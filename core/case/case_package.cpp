#include "case/case_package.hpp"

#include "case/detail/zip_archive.hpp"
#include "case/sha256.hpp"
#include "case/signing.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace viscera::vcase {

using sim::displayName;
using sim::entryNameProblem;
namespace detail {
/// The package in memory after checks (a) to (h).
struct VerifiedPackage {
    Manifest manifest;
    std::string manifestText;
    std::optional<PackageSignature> signature;
    std::string sha256; ///< of the whole package
    uint64_t bytes = 0;
    std::map<std::string, std::string, std::less<>> files;
};
} // namespace detail

namespace {

using Verified = detail::VerifiedPackage;

// Unix st_mode file types as stored in zip external attributes (host independent).
constexpr uint32_t kTypeMask = 0170000;
constexpr uint32_t kTypeRegular = 0100000;
constexpr uint32_t kTypeDirectory = 0040000;
constexpr uint32_t kTypeSymlink = 0120000;

/// The smallest possible zip archive: an end-of-central-directory record.
constexpr size_t kMinZipBytes = 22;

/// Messages are "<package>: <rule>" or "<package>: <entry or field>: <rule>".
class Failure {
public:
    explicit Failure(const std::string& package) : m_package(package) {}
    [[noreturn]] void package(const std::string& rule) const { throw InputError(m_package + ": " + rule); }
    [[noreturn]] void entry(std::string_view name, const std::string& rule) const {
        throw InputError(m_package + ": " + displayName(name) + ": " + rule);
    }
    std::string origin(std::string_view name) const { return m_package + ": " + std::string(name); }

private:
    const std::string& m_package;
};

std::string bytesText(uint64_t n) {
    return std::to_string(n) + " bytes";
}

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; });
    return out;
}

struct Entry {
    detail::ZipEntryInfo info;
    uint64_t index = 0;
    bool directory = false;
};

/// (c) names, entry types, duplicates, directories.
void checkNames(const Failure& fail, const std::vector<Entry>& entries) {
    std::set<std::string, std::less<>> exact;
    std::map<std::string, std::string> folded; // lower-case name without trailing '/' -> name
    std::set<std::string, std::less<>> fileNames;
    for (const Entry& e : entries) {
        const std::string& name = e.info.name;
        std::string_view path =
            e.directory ? std::string_view(name).substr(0, name.size() - 1) : std::string_view(name);
        if (auto problem = entryNameProblem(path)) fail.entry(name, *problem);

        uint32_t type = e.info.unixMode & kTypeMask;
        if (type == kTypeSymlink) fail.entry(name, "symbolic link entries are not allowed");
        if (type != 0 && type != kTypeRegular && type != kTypeDirectory) {
            char octal[16];
            std::snprintf(octal, sizeof octal, "0%o", static_cast<unsigned>(type));
            fail.entry(name, std::string("entry is not a regular file (Unix file type ") + octal + ")");
        }
        if (!e.directory && (type == kTypeDirectory || e.info.dosDirectory))
            fail.entry(name, "directory entry without a trailing '/'");
        if (e.directory && e.info.size != 0) fail.entry(name, "directory entry holds data");

        if (!exact.insert(name).second) fail.entry(name, "duplicate entry");
        auto [it, fresh] = folded.emplace(lower(path), name);
        if (!fresh)
            fail.entry(name, "entry name collides with '" + displayName(it->second) +
                                 "' (names must differ other than in letter case or a trailing '/')");
        if (!e.directory) fileNames.insert(name);
    }
    for (const Entry& e : entries) {
        const std::string& name = e.info.name;
        if (e.directory) {
            auto it = fileNames.lower_bound(name);
            if (it == fileNames.end() || !it->starts_with(name))
                fail.entry(name, "directory entry contains no packaged file (only parents of "
                                 "files may appear)");
            continue;
        }
        for (size_t slash = name.find('/'); slash != std::string::npos; slash = name.find('/', slash + 1))
            if (fileNames.count(std::string_view(name).substr(0, slash)))
                fail.entry(name, "entry lies under the file entry '" + displayName(name.substr(0, slash)) + "'");
    }
}

/// (d) compression method, encryption, uncompressed sizes and compression ratio, per entry and
/// for the whole package of `packageBytes` (many small entries that each pass the per-entry rule
/// can still expand a small package a thousandfold).
void checkSizes(const Failure& fail, const std::vector<Entry>& entries, const Limits& limits, uint64_t packageBytes) {
    uint64_t total = 0;
    for (const Entry& e : entries) {
        const detail::ZipEntryInfo& info = e.info;
        if (info.encrypted) fail.entry(info.name, "entry is encrypted (not supported)");
        if (!info.compressionSupported)
            fail.entry(info.name, "compression method " + std::to_string(info.compressionMethod) +
                                      " is not supported (use store or deflate)");
        if (info.size > limits.maxEntryBytes)
            fail.entry(info.name, "uncompressed size " + bytesText(info.size) + " exceeds the per-entry limit of " +
                                      bytesText(limits.maxEntryBytes));
        double ratio = double(info.size) / double(std::max<uint64_t>(info.compressedSize, 1));
        if (info.size >= limits.ratioMinBytes && ratio > limits.maxCompressionRatio)
            fail.entry(info.name,
                       "compression ratio " + std::to_string(std::llround(ratio)) + ":1 exceeds the limit of " +
                           std::to_string(std::llround(limits.maxCompressionRatio)) + ":1 (possible zip bomb)");
        total += info.size; // each term <= maxEntryBytes, so no overflow before the check below
        if (total > limits.maxTotalBytes)
            fail.package("total uncompressed size exceeds the limit of " + bytesText(limits.maxTotalBytes) +
                         " (reached at entry '" + displayName(info.name) + "')");
    }
    const double expansion = double(total) / double(std::max<uint64_t>(packageBytes, 1));
    if (total >= limits.ratioMinBytes && expansion > limits.maxCompressionRatio)
        fail.package("the entries expand to " + bytesText(total) + ", " + std::to_string(std::llround(expansion)) +
                     " times the package's " + bytesText(packageBytes) + ", more than the limit of " +
                     std::to_string(std::llround(limits.maxCompressionRatio)) + ":1 (possible zip bomb)");
}

std::string readEntry(const Failure& fail, const detail::ZipReader& zip, const Entry& e) {
    try {
        return zip.read(e.index, e.info.size);
    } catch (const detail::ZipError& error) {
        fail.entry(e.info.name, std::string("cannot decompress entry (corrupt data: ") + error.what() + ")");
    }
}

/// (e') signature.json, when present: small, and well formed (whether it is valid and trusted is
/// the player's check, vcase::checkProvenance).
std::optional<PackageSignature> readSignature(const Failure& fail, const detail::ZipReader& zip,
                                              const std::map<std::string_view, const Entry*>& files) {
    auto it = files.find(kSignatureName);
    if (it == files.end()) return std::nullopt;
    const Entry& e = *it->second;
    if (e.info.size > kMaxSignatureBytes)
        fail.entry(kSignatureName, "size " + bytesText(e.info.size) + " exceeds the signature limit of " +
                                       bytesText(kMaxSignatureBytes));
    return PackageSignature::parse(readEntry(fail, zip, e), fail.origin(kSignatureName));
}

/// (a) to (d): the archive's directory, every rule that needs no entry's data.
struct Archive {
    std::unique_ptr<detail::ZipReader> zip;
    std::vector<Entry> entries;
    std::map<std::string_view, const Entry*> files; ///< file entries by name (names are unique)
};

Archive openArchive(const Failure& fail, std::string_view bytes, const Limits& limits) {
    // (a) size; existence and readability were checked by the caller that read the file.
    if (bytes.size() > limits.maxPackageBytes)
        fail.package("package is " + bytesText(bytes.size()) + ", larger than the limit of " +
                     bytesText(limits.maxPackageBytes));
    // (b) zip container, entry count.
    Archive a;
    try {
        if (bytes.size() < kMinZipBytes) throw detail::ZipError("too short for a zip archive");
        a.zip = detail::ZipReader::open(bytes);
    } catch (const detail::ZipError& error) {
        fail.package(std::string("not a valid zip archive (truncated or corrupt): ") + error.what());
    }
    const uint64_t count = a.zip->entryCount();
    if (count > limits.maxEntries)
        fail.package("package has " + std::to_string(count) + " entries, more than the limit of " +
                     std::to_string(limits.maxEntries));
    a.entries.reserve(count);
    for (uint64_t i = 0; i < count; ++i) {
        Entry e;
        try {
            e.info = a.zip->entry(i);
        } catch (const detail::ZipError& error) {
            fail.package("not a valid zip archive (truncated or corrupt): entry " + std::to_string(i) + ": " +
                         error.what());
        }
        e.index = i;
        e.directory = !e.info.name.empty() && e.info.name.back() == '/';
        a.entries.push_back(std::move(e));
    }
    // (c) names; (d) sizes.
    checkNames(fail, a.entries);
    checkSizes(fail, a.entries, limits, bytes.size());
    for (const Entry& e : a.entries)
        if (!e.directory) a.files.emplace(e.info.name, &e);
    return a;
}

/// (e) manifest.json and signature.json, the only entries inflated before the admission check.
void readHead(const Failure& fail, const Archive& a, const Limits& limits, Verified& out) {
    auto manifestEntry = a.files.find(kManifestName);
    if (manifestEntry == a.files.end())
        fail.entry(kManifestName, "missing (a package needs manifest.json at its root)");
    const Entry& me = *manifestEntry->second;
    if (me.info.size > limits.maxManifestBytes)
        fail.entry(kManifestName, "size " + bytesText(me.info.size) + " exceeds the manifest limit of " +
                                      bytesText(limits.maxManifestBytes));
    out.manifestText = readEntry(fail, *a.zip, me);
    out.manifest = Manifest::parse(out.manifestText, fail.origin(kManifestName));
    out.signature = readSignature(fail, *a.zip, a.files);
}

/// (f) listed files: present, size, sha256; then nothing unlisted.
void readListedFiles(const Failure& fail, const Archive& a, Verified& out) {
    for (const FileEntry& listed : out.manifest.files) {
        auto it = a.files.find(listed.path);
        if (it == a.files.end()) fail.entry(listed.path, "listed in manifest.json but missing from the package");
        const Entry& e = *it->second;
        if (e.info.size != listed.size)
            fail.entry(listed.path, "size mismatch (manifest says " + bytesText(listed.size) + ", entry has " +
                                        bytesText(e.info.size) + ")");
        std::string data = readEntry(fail, *a.zip, e);
        std::string hash = sha256Hex(data);
        if (hash != listed.sha256)
            fail.entry(listed.path, "sha256 mismatch (manifest says " + listed.sha256 + ", file has " + hash + ")");
        out.files.emplace(listed.path, std::move(data));
    }
    for (const Entry& e : a.entries)
        if (!e.directory && e.info.name != kManifestName && e.info.name != kSignatureName &&
            !out.files.count(e.info.name))
            fail.entry(e.info.name, "file is not listed in manifest.json");
}

/// (h) meshes.
void parseMeshes(const std::string& name, const Verified& v) {
    for (const auto& [path, data] : v.files) {
        if (!path.ends_with(".vtet")) continue;
        try {
            sim::parseVtet(data, name + ":" + path);
        } catch (const std::invalid_argument& error) {
            // Mesh-level rules (TetMesh::fromArrays) name the same origin; report as input.
            throw InputError(error.what());
        }
    }
}

PackageHead headOf(const std::string& name, const Verified& v) {
    return PackageHead{name, v.manifest, v.manifestText, v.signature, v.sha256, v.bytes};
}

/// (a) to (e) and (g), the admission check, then (f) and (h). `headOnly`: stop after the admission check.
Verified verifyBytes(std::string_view bytes, const std::string& name, const Limits& limits, const Admission& admit,
                     bool headOnly = false) {
    if (!(limits.maxCompressionRatio > 0))
        throw std::invalid_argument("vcase::Limits: maxCompressionRatio must be positive");
    const Failure fail(name);
    const Archive archive = openArchive(fail, bytes, limits);
    Verified out;
    readHead(fail, archive, limits, out);
    // (g) compatibility with this player: the manifest's alone, so before the admission too.
    checkPlayerCompatibility(out.manifest, fail.origin(kManifestName));
    out.sha256 = sha256Hex(bytes);
    out.bytes = bytes.size();
    // Whose package it is, before any other entry is inflated: an untrusted or unsigned package
    // costs its directory and two small entries, never its payload.
    if (admit) admit(headOf(name, out));
    if (headOnly) return out;
    readListedFiles(fail, archive, out);
    parseMeshes(name, out);
    return out;
}

Verified verifyFile(const std::filesystem::path& path, const Limits& limits, const Admission& admit,
                    bool headOnly = false) {
    namespace fs = std::filesystem;
    const std::string name = path.string();
    const Failure fail(name);
    std::error_code ec;
    fs::file_status status = fs::status(path, ec);
    if (status.type() == fs::file_type::not_found) fail.package("cannot open package (file does not exist)");
    if (ec) fail.package("cannot open package (" + ec.message() + ")");
    if (!fs::is_regular_file(status)) fail.package("cannot open package (not a regular file)");
    uint64_t size = fs::file_size(path, ec);
    if (ec) fail.package("cannot open package (" + ec.message() + ")");
    if (size > limits.maxPackageBytes)
        fail.package("package is " + bytesText(size) + ", larger than the limit of " +
                     bytesText(limits.maxPackageBytes));
    std::string bytes = readFile(path, limits.maxPackageBytes); // InputError "<path>: ..."
    return verifyBytes(bytes, name, limits, admit, headOnly);
}

} // namespace

std::unique_ptr<CasePackage> CasePackage::make(std::string name, detail::VerifiedPackage&& v) {
    std::unique_ptr<CasePackage> package(new CasePackage());
    package->m_name = std::move(name);
    package->m_manifest = std::move(v.manifest);
    package->m_manifestText = std::move(v.manifestText);
    package->m_signature = std::move(v.signature);
    package->m_sha256 = std::move(v.sha256);
    package->m_bytes = v.bytes;
    package->m_files = std::move(v.files);
    return package;
}

std::unique_ptr<CasePackage> CasePackage::open(const std::filesystem::path& path, const Limits& limits,
                                               const Admission& admit) {
    return make(path.string(), verifyFile(path, limits, admit));
}

std::unique_ptr<CasePackage> CasePackage::fromBytes(std::string_view bytes, std::string name, const Limits& limits,
                                                    const Admission& admit) {
    Verified v = verifyBytes(bytes, name, limits, admit);
    return make(std::move(name), std::move(v));
}

CasePackage::~CasePackage() = default;

bool CasePackage::contains(std::string_view path) const {
    return m_files.find(path) != m_files.end();
}

std::string_view CasePackage::read(std::string_view path) const {
    auto it = m_files.find(path);
    if (it == m_files.end()) throw InputError(m_name + ": " + displayName(path) + ": not listed in manifest.json");
    return it->second;
}

Manifest verify(const std::filesystem::path& path, const Limits& limits) {
    return verifyFile(path, limits, {}).manifest;
}

void readPackageHead(const std::filesystem::path& path, const Admission& admit, const Limits& limits) {
    (void)verifyFile(path, limits, admit, true);
}

void readPackageHead(std::string_view bytes, const std::string& name, const Admission& admit, const Limits& limits) {
    (void)verifyBytes(bytes, name, limits, admit, true);
}

PackageHead CasePackage::head() const {
    return PackageHead{m_name, m_manifest, m_manifestText, m_signature, m_sha256, m_bytes};
}

} // namespace viscera::vcase
