#pragma once
// A temporary folder for one test, removed with everything in it at the end of the scope.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace viscera::test {

struct Scratch {
    std::filesystem::path dir;
    explicit Scratch(const std::string& prefix = "viscera-test") {
        dir = std::filesystem::temp_directory_path() /
              (prefix + "-" + std::to_string(::getpid()) + "-" + std::to_string(std::rand()));
        std::filesystem::create_directories(dir);
    }
    ~Scratch() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
    Scratch(const Scratch&) = delete;
    Scratch& operator=(const Scratch&) = delete;
    std::string operator/(const std::string& name) const { return (dir / name).string(); }
};

} // namespace viscera::test
