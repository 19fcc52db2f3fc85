#pragma once
/// Semantic versions (https://semver.org, 2.0.0): MAJOR.MINOR.PATCH[-PRERELEASE][+BUILD].
/// Used for a case's own version and for the oldest player that can run it.
#include <compare>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace viscera::vcase {

struct SemVer {
    uint64_t major = 0;
    uint64_t minor = 0;
    uint64_t patch = 0;
    std::string prerelease; ///< dot-separated identifiers ("rc.1"); empty for a release
    std::string build;      ///< dot-separated identifiers; ignored by compare()

    /// Strict parse: no leading 'v', no leading zeros in numeric identifiers, no empty
    /// identifiers, identifiers use [0-9A-Za-z-]. Returns nullopt when the text is not a
    /// semantic version. O(length).
    static std::optional<SemVer> parse(std::string_view text);
    std::string toString() const;

    friend bool operator==(const SemVer&, const SemVer&) = default;
};

/// Precedence (semver §11): numeric MAJOR, MINOR, PATCH; a pre-release sorts before its release;
/// pre-release identifiers compare numerically when both are numeric, numeric before
/// alphanumeric, otherwise in ASCII order; build metadata is ignored.
std::strong_ordering compare(const SemVer& a, const SemVer& b);

/// This player's version (the VISCERA_VERSION compile definition, e.g. "0.1.0").
const SemVer& playerVersion();

} // namespace viscera::vcase
