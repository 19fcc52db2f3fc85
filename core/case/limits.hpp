#pragma once
/// Resource limits applied when a .vcase package is opened, against oversized packages and zip
/// bombs. Sizes are bytes; the defaults suit every case the product ships.
#include <cstdint>

namespace viscera::vcase {

struct Limits {
    uint64_t maxPackageBytes = 512ull << 20; ///< the .vcase file itself (512 MiB)
    uint64_t maxEntries = 4096;              ///< zip entries, directories included
    uint64_t maxEntryBytes = 256ull << 20;   ///< uncompressed, per entry (256 MiB)
    uint64_t maxTotalBytes = 1ull << 30;     ///< uncompressed, all entries (1 GiB)
    uint64_t maxManifestBytes = 1ull << 20;  ///< uncompressed manifest.json (1 MiB)
    /// Uncompressed : compressed, per entry, and all entries' uncompressed size : the package's size.
    double maxCompressionRatio = 200.0;
    /// Entries smaller than this (uncompressed) skip the per-entry ratio rule: tiny files compress
    /// extremely well; the whole-package rule applies once all entries together reach this size.
    uint64_t ratioMinBytes = 1ull << 20;
};

} // namespace viscera::vcase
