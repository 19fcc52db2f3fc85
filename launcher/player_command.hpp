#pragma once
/// The command line the launcher starts a case with, and the function that starts it. The window
/// builds a PlayerCommand and hands it to a Launch function: the real one starts the player and
/// watches it (launchWatched), a test's records it.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::launcher {

/// What every start passes to the player besides the case (the launcher's own options).
struct LaunchSettings {
    std::string player = "viscera-player"; ///< program: a path, or a name looked up in PATH
    std::string device;                    ///< --device SPEC for every run; empty: the player's default
    std::string pairingKey;                ///< --pairing-key FILE; empty: none
    std::vector<std::string> trustKeys;    ///< --trust KEY.pem for every run (the launcher trusts them too)
};

struct PlayerCommand {
    std::string program;
    std::vector<std::string> arguments;
    /// The command as one shell-like line, for messages: words with spaces are quoted.
    std::string display() const;
};

/// True when the player understands `--trainee ID` (viscera-player run records it in the report,
/// for viscera-results). Set it false for a player without the option: the id is then checked
/// and shown, not passed on (TRAINEE_OPTION in player_command.cpp).
inline constexpr bool kPlayerHasTraineeOption = true;

/// A trainee id: 1 to 64 characters of A-Z a-z 0-9 . _ - @ (a badge number, a login), the rule
/// of viscera-player's --trainee.
inline constexpr size_t kMaxTraineeIdLength = 64;
bool isTraineeIdCharacter(char c);
/// Empty when `id` is a valid trainee id, else one line saying why.
std::string traineeIdProblem(std::string_view id);

/// `player run CASE` in the trainee window, with the settings' device and pairing key, and
/// `--trainee ID` for a non-empty id (TRAINEE_OPTION, while kPlayerHasTraineeOption).
PlayerCommand playerCommand(const LaunchSettings& settings, const std::filesystem::path& caseFile,
                            std::string_view traineeId);

/// Called once a started player has exited: its exit status (non-zero: the case did not run to
/// its end) and its one-line reason (the last line it wrote to stderr, without the program's name;
/// control characters removed). Called on the launcher's thread.
using ExitHandler = std::function<void(int exitCode, const std::string& reason)>;

/// Starts a command and calls `onExit` when it ends; returns an empty string on success, else one
/// line saying why it could not start.
using Launch = std::function<std::string(const PlayerCommand&, ExitHandler onExit)>;
/// Starts the command as a child of the launcher (QProcess), reading its stderr for the reason
/// it gives when it refuses a case or fails. The player's own stdout is discarded.
std::string launchWatched(const PlayerCommand& command, ExitHandler onExit);
/// The reason in a player's stderr: its last non-empty line, "viscera-player: " dropped, control
/// characters replaced by spaces, at most 300 characters.
std::string exitReason(std::string_view stderrText);

} // namespace viscera::launcher
