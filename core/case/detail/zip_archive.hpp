#pragma once
/// Internal to viscera::case: the zip container, kept behind plain types so that no libzip type
/// reaches a header. The package rules (names, limits, manifest) live in case_package.cpp; this
/// layer only reads and writes archives. Errors are detail::ZipError with libzip's wording.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::vcase::detail {

class ZipError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Central-directory facts about one entry (declared, not yet checked against the data).
struct ZipEntryInfo {
    std::string name;            ///< raw bytes of the stored name
    uint64_t size = 0;           ///< declared uncompressed size, bytes
    uint64_t compressedSize = 0; ///< bytes
    int32_t compressionMethod = 0;
    bool compressionSupported = false; ///< stored or deflated
    bool encrypted = false;
    uint32_t unixMode = 0;     ///< st_mode from the external attributes (0 when not a Unix entry)
    bool dosDirectory = false; ///< MS-DOS directory attribute bit
};

/// Read-only view of an archive held in memory. Non-copyable.
class ZipReader {
public:
    /// Opens the archive in `bytes`, which must outlive the reader. Consistency checks between
    /// the central directory and the local headers are on; an archive whose only defect is a
    /// repeated entry name still opens (the caller reports the duplicate). Throws ZipError.
    static std::unique_ptr<ZipReader> open(std::string_view bytes);
    ~ZipReader();
    ZipReader(const ZipReader&) = delete;
    ZipReader& operator=(const ZipReader&) = delete;

    uint64_t entryCount() const;
    ZipEntryInfo entry(uint64_t index) const;
    /// Decompresses entry `index`, which must yield exactly `declaredSize` bytes with a matching
    /// CRC-32; never allocates more than `declaredSize`. Throws ZipError otherwise. O(size).
    std::string read(uint64_t index, uint64_t declaredSize) const;

private:
    struct Impl;
    explicit ZipReader(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

struct ZipInput {
    std::string_view name;
    std::string_view bytes;
};

/// A deterministic archive of `entries`, in the given order: deflate level 9, every timestamp
/// 1980-01-01 00:00:00, Unix mode 0644, no comment and no extra fields, so equal input gives
/// byte-identical output (for a given zlib). Throws ZipError.
std::string writeZip(const std::vector<ZipInput>& entries);

} // namespace viscera::vcase::detail
