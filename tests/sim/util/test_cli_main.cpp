#include "sim/util/cli_main.hpp"
#include "sim/util/error.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

using namespace viscera::sim;

namespace {

int runWith(const CliProgram& program, std::vector<std::string> args) {
    std::vector<char*> argv;
    std::string name = "prog";
    argv.push_back(name.data());
    for (std::string& a : args)
        argv.push_back(a.data());
    return runCli(program, static_cast<int>(argv.size()), argv.data());
}

CliProgram throwing(std::function<void()> what) {
    CliProgram p;
    p.name = "prog";
    p.subcommands = {{"go", [what](const CliArgs&) {
                          what();
                          return kExitOk;
                      }}};
    return p;
}

} // namespace

TEST(RunCli, DispatchesSubcommandsWithTheRemainingArguments) {
    CliArgs seen;
    CliProgram p;
    p.name = "prog";
    p.subcommands = {{"a", [](const CliArgs&) { return 7; }}, {"b", [&](const CliArgs& args) {
                                                                   seen = args;
                                                                   return kExitOk;
                                                               }}};
    EXPECT_EQ(runWith(p, {"a"}), 7);
    EXPECT_EQ(runWith(p, {"b", "x", "--y"}), kExitOk);
    EXPECT_EQ(seen, (CliArgs{"x", "--y"}));
    EXPECT_EQ(runWith(p, {}), kExitUsage);
    EXPECT_EQ(runWith(p, {"nope"}), kExitUsage);
    EXPECT_EQ(runWith(p, {"--version"}), kExitUsage); // no version given
}

TEST(RunCli, FallbackAndNoArgumentsActions) {
    CliArgs seen;
    CliProgram p;
    p.name = "prog";
    p.fallback = [&](const CliArgs& args) {
        seen = args;
        return 5;
    };
    p.noArguments = [] { return 4; };
    EXPECT_EQ(runWith(p, {"--listen", "h:1"}), 5);
    EXPECT_EQ(seen, (CliArgs{"--listen", "h:1"}));
    EXPECT_EQ(runWith(p, {}), 4);
}

TEST(RunCli, MapsExceptionsToExitCodes) {
    EXPECT_EQ(kExitOk, 0);
    EXPECT_EQ(kExitInput, 1);
    EXPECT_EQ(kExitUsage, 2);
    EXPECT_EQ(kExitInvariant, 3);
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(runWith(throwing([] { throw viscera::InputError("bad case"); }), {"go"}), kExitInput);
    EXPECT_EQ(runWith(throwing([] { throw std::invalid_argument("bad flag"); }), {"go"}), kExitUsage);
    EXPECT_EQ(runWith(throwing([] { throw std::runtime_error("bug"); }), {"go"}), kExitInput);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "prog: bad case\nprog: bad flag\nprog: internal error: bug\n");
}
