#pragma once
/// The shared main() of the command-line programs (viscera-player, viscera-studio,
/// viscera-console-sim): subcommand dispatch, --help / -h, --version, and one mapping from
/// exceptions to exit codes and "<program>: <message>" lines on stderr. For executables only: the
/// libraries never print, this is where a program does.
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

/// Exit codes of every Viscera program.
inline constexpr int kExitOk = 0;        ///< success
inline constexpr int kExitInput = 1;     ///< bad input (case, project, file, argument value) or an internal error
inline constexpr int kExitUsage = 2;     ///< wrong usage (unknown subcommand, missing or malformed argument)
inline constexpr int kExitInvariant = 3; ///< the run broke an invariant

using CliArgs = std::vector<std::string>;
using CliAction = std::function<int(const CliArgs& args)>;

/// `program <name> args...`; `run` gets the arguments after the name. `program <name> ... --help`
/// (or -h anywhere after the name) prints `help` to stdout and exits 0 without running it.
struct CliSubcommand {
    std::string_view name;
    CliAction run;
    std::string_view help; ///< the subcommand's usage and options; empty: the program's usage
};

struct CliProgram {
    const char* name = "";                   ///< "viscera-player": prefixes every stderr line
    const char* version = nullptr;           ///< --version prints "<name> <version>"; null: none
    void (*usage)(std::FILE* out) = nullptr; ///< --help / -h print it to stdout, a usage error to stderr
    std::vector<CliSubcommand> subcommands;
    /// Runs with all the arguments when the first one is no subcommand, --help, -h or --version;
    /// empty: usage on stderr, kExitUsage.
    CliAction fallback;
    /// Runs when there are no arguments (a GUI, for one); empty: usage on stderr, kExitUsage.
    std::function<int()> noArguments;
};

/// Dispatches argv and maps what the action throws: viscera::InputError → kExitInput,
/// std::invalid_argument → kExitUsage, any other std::exception → kExitInput with
/// "internal error: " before its message; each printed as one "<name>: <message>" line on stderr.
int runCli(const CliProgram& program, int argc, char** argv);

/// Prints "<program>: <message>" on stderr and returns `code`.
int cliFail(const char* program, int code, const std::string& message);

} // namespace viscera::sim
