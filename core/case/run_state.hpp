#pragma once
/// The player's record of the case versions it has run, for refusing a rollback: a state folder
/// holding case-versions.json, {"schemaVersion": 1, "cases": {"<caseId>": "<highest caseVersion>"}},
/// written atomically.
#include <filesystem>
#include <optional>
#include <string>

namespace viscera::vcase {

inline constexpr std::string_view kRunStateName = "case-versions.json";

/// The highest version of `caseId` recorded in `folder`, or nullopt. Throws viscera::InputError
/// naming the file when it is malformed (it is then left as it is).
std::optional<std::string> highestVersionRun(const std::filesystem::path& folder, const std::string& caseId);

/// Records that `version` of `caseId` ran, when it is higher than the recorded one. Throws
/// viscera::InputError naming the file when it is malformed or cannot be written.
void recordVersionRun(const std::filesystem::path& folder, const std::string& caseId, const std::string& version);

} // namespace viscera::vcase
