#pragma once
// The tests' cases are signed with the sample publisher key the build makes (VISCERA_SAMPLE_KEY,
// a test key) and the player under test trusts its public half: these add the options to a
// command line. Tests of the signature rules themselves build their command lines by hand.
#include <string>
#include <vector>

namespace viscera::test {

/// viscera-player run, verify and soak: + --trust <sample public key>.
inline std::vector<std::string> trustingSampleKey(std::vector<std::string> args) {
    if (!args.empty() && (args[0] == "run" || args[0] == "verify" || args[0] == "soak")) {
        args.insert(args.begin() + 1,
                    {"--trust", VISCERA_SAMPLE_PUBLIC_KEY}); // before any option left without its value
    }
    return args;
}

/// viscera-studio export: + --sign-key <sample key>.
inline std::vector<std::string> signingWithSampleKey(std::vector<std::string> args) {
    if (!args.empty() && args[0] == "export") {
        args.insert(args.begin() + 1, {"--sign-key", VISCERA_SAMPLE_KEY});
    }
    return args;
}

} // namespace viscera::test
