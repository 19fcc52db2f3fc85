#pragma once
/// Test helpers: hand-made .vcase archives (valid or deliberately broken) and a scratch folder.
#include "case/manifest.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace viscera::vcase::test {

struct RawEntry {
    static constexpr int32_t kByFlag = -2; ///< method: deflate or store according to `deflate`

    RawEntry(std::string name_, std::string bytes_, bool deflate_ = true,
             std::optional<uint32_t> unixMode_ = std::nullopt, int32_t method_ = kByFlag)
        : name(std::move(name_)), bytes(std::move(bytes_)), deflate(deflate_), unixMode(unixMode_), method(method_) {}

    std::string name;
    std::string bytes;
    bool deflate;
    std::optional<uint32_t> unixMode; ///< st_mode for the external attributes; 0100644 if unset
    int32_t method;                   ///< libzip compression method, or kByFlag
};

/// A zip of `entries` in the given order, written with libzip without any name checks.
std::string craftZip(const std::vector<RawEntry>& entries);

/// A valid manifest (schema 1, player 0.1.0) listing `files` with their true sizes and hashes.
Manifest manifestFor(const std::vector<RawEntry>& files);

/// manifest.json (text of `manifest`) followed by `files`, zipped.
std::string craftPackage(const Manifest& manifest, const std::vector<RawEntry>& files);

/// A valid one-tetrahedron .vtet mesh (metres).
std::string unitTetVtet();

/// Replaces every occurrence of `from` with `to` (same length) in `bytes`; returns the count.
size_t patchBytes(std::string& bytes, const std::string& from, const std::string& to);

/// The one-line message of the viscera::InputError `f` throws, or "(no error)".
std::string messageOf(const std::function<void()>& f);

/// A fresh folder under the system temp folder, removed with its contents on destruction.
class ScratchDir {
public:
    ScratchDir();
    ~ScratchDir();
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    const std::filesystem::path& path() const { return m_path; }
    /// Writes `bytes` to `<dir>/<name>` and returns the path.
    std::filesystem::path write(const std::string& name, const std::string& bytes) const;

private:
    std::filesystem::path m_path;
};

} // namespace viscera::vcase::test
