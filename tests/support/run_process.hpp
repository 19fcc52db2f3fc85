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

/// Starts `exe args...` in the background, stdout and stderr to <logPrefix>.out and .err;
/// waitFor() reaps it and gives its exit code (-1: killed or not started); the destructor of a
/// process still running stops it (SIGTERM).
struct Background {
    int pid = -1;
    Background(const std::string& exe, const std::vector<std::string>& args, const std::string& logPrefix);
    int waitFor();
    ~Background();
    Background(const Background&) = delete;
    Background& operator=(const Background&) = delete;
};

} // namespace viscera::test
