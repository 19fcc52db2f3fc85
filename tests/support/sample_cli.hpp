#pragma once
// The end-to-end tests' way to run the two programs on signed sample cases (case_signing.hpp) and
// read what they write. Needs VISCERA_PLAYER_EXE and VISCERA_STUDIO_EXE (viscera_add_cli_test).
#include "support/case_signing.hpp"
#include "support/run_process.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace viscera::test {

/// viscera-player trusting the sample key.
inline ProcessResult samplePlayer(const std::vector<std::string>& args) {
    return runProcess(VISCERA_PLAYER_EXE, trustingSampleKey(args));
}
/// viscera-studio signing with the sample key.
inline ProcessResult sampleStudio(const std::vector<std::string>& args) {
    return runProcess(VISCERA_STUDIO_EXE, signingWithSampleKey(args));
}
inline std::string readTextFile(const std::filesystem::path& p) {
    std::ifstream in(p);
    return {std::istreambuf_iterator<char>(in), {}};
}
inline nlohmann::json readJsonFile(const std::filesystem::path& p) {
    return nlohmann::json::parse(readTextFile(p));
}

} // namespace viscera::test
