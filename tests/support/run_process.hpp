#pragma once
// Runs a command-line tool for end-to-end tests and captures its exit code, stdout and stderr.
#include <filesystem>
#include <string>
#include <vector>

namespace viscera::test {

struct ProcessResult {
    int exitCode = -1;
    std::string out, err;
};

/// Runs `exe args...` without a shell (posix_spawn), with stdin from /dev/null.
ProcessResult runProcess(const std::string& exe, const std::vector<std::string>& args);

} // namespace viscera::test
