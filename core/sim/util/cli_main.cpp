#include "sim/util/cli_main.hpp"

#include "sim/util/error.hpp"

#include <exception>
#include <stdexcept>

namespace viscera::sim {
namespace {

int usageError(const CliProgram& program) {
    if (program.usage) program.usage(stderr);
    return kExitUsage;
}

int dispatch(const CliProgram& program, const CliArgs& args) {
    if (args.empty()) return program.noArguments ? program.noArguments() : usageError(program);
    const std::string& cmd = args[0];
    for (const CliSubcommand& sub : program.subcommands)
        if (cmd == sub.name) {
            for (size_t i = 1; i < args.size(); ++i)
                if (args[i] == "--help" || args[i] == "-h") {
                    if (!sub.help.empty())
                        std::fwrite(sub.help.data(), 1, sub.help.size(), stdout);
                    else if (program.usage)
                        program.usage(stdout);
                    return kExitOk;
                }
            return sub.run(CliArgs(args.begin() + 1, args.end()));
        }
    if (program.version && cmd == "--version") {
        std::printf("%s %s\n", program.name, program.version);
        return kExitOk;
    }
    if (cmd == "--help" || cmd == "-h") {
        if (program.usage) program.usage(stdout);
        return kExitOk;
    }
    return program.fallback ? program.fallback(args) : usageError(program);
}

} // namespace

int cliFail(const char* program, int code, const std::string& message) {
    std::fprintf(stderr, "%s: %s\n", program, message.c_str());
    return code;
}

int runCli(const CliProgram& program, int argc, char** argv) {
    const CliArgs args(argv + 1, argv + argc);
    try {
        return dispatch(program, args);
    } catch (const InputError& e) {
        return cliFail(program.name, kExitInput, e.what());
    } catch (const std::invalid_argument& e) {
        return cliFail(program.name, kExitUsage, e.what());
    } catch (const std::exception& e) {
        return cliFail(program.name, kExitInput, std::string("internal error: ") + e.what());
    }
}

} // namespace viscera::sim
