#include "case/case_writer.hpp"

#include "case/case_package.hpp"
#include "case/detail/zip_archive.hpp"
#include "case/sha256.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <vector>

namespace viscera::vcase {

using sim::displayName;
using sim::entryNameProblem;
namespace {

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; });
    return out;
}

} // namespace

CaseWriter::CaseWriter(Manifest header) : m_header(std::move(header)) {
    if (!m_header.files.empty())
        throw InputError("vcase::CaseWriter: files: must be empty (write() lists the added files)");
    Manifest::fromJson(m_header.toJson(), "vcase::CaseWriter"); // schema check, throws InputError
}

void CaseWriter::addFile(std::string_view path, std::string bytes) {
    const std::string origin = "vcase::CaseWriter::addFile(): " + displayName(path) + ": ";
    if (auto problem = entryNameProblem(path)) throw InputError(origin + *problem);
    if (path == kManifestName) throw InputError(origin + "reserved name (the writer generates manifest.json)");
    if (path == kSignatureName) throw InputError(origin + "reserved name (sign() makes signature.json)");
    auto [it, fresh] = m_foldedPaths.emplace(lower(path), std::string(path));
    if (!fresh)
        throw InputError(origin + (it->second == path
                                       ? "already added"
                                       : "collides with '" + it->second + "' (names differ only in letter case)"));
    m_files.emplace(std::string(path), std::move(bytes));
}

void CaseWriter::sign(const SigningKey& key, std::string signer) {
    m_key = &key;
    m_signer = std::move(signer);
}

Manifest CaseWriter::manifest() const {
    Manifest m = m_header;
    for (const auto& [path, data] : m_files)
        m.files.push_back({path, data.size(), sha256Hex(data)});
    return m;
}

std::string CaseWriter::buildNamed(const std::string& name, const Limits& limits, Manifest* written,
                                   std::string* sha256) const {
    Manifest m = manifest();
    const std::string manifestText = m.toJsonText();
    std::vector<detail::ZipInput> inputs;
    inputs.reserve(m_files.size() + 1);
    inputs.push_back({kManifestName, manifestText});
    const std::string signatureText = m_key ? signManifest(*m_key, m_signer, manifestText) : std::string();
    if (m_key) inputs.push_back({kSignatureName, signatureText});
    for (const auto& [path, data] : m_files)
        inputs.push_back({path, data});
    std::string bytes;
    try {
        bytes = detail::writeZip(inputs);
    } catch (const detail::ZipError& error) {
        throw InputError(name + ": cannot build the zip archive: " + error.what());
    }
    const auto verified = CasePackage::fromBytes(bytes, name, limits); // the player's checks, throws InputError
    if (sha256) *sha256 = verified->sha256();
    if (written) *written = std::move(m);
    return bytes;
}

std::string CaseWriter::build(const Limits& limits) const {
    return buildNamed("vcase::CaseWriter::build()", limits, nullptr, nullptr);
}

Manifest CaseWriter::write(const std::filesystem::path& path, const Limits& limits, std::string* sha256) const {
    Manifest written;
    std::string bytes = buildNamed(path.string(), limits, &written, sha256);
    writeFileAtomic(path, bytes);
    return written;
}

} // namespace viscera::vcase
