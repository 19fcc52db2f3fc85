#pragma once
/// The command line the launcher starts a case with, and the function that starts it. The window
/// builds a PlayerCommand and hands it to a Launch function: the real one starts the player
/// detached (QProcess::startDetached), a test's records it.
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

/// Starts a command; returns an empty string on success, else one line saying why not.
using Launch = std::function<std::string(const PlayerCommand&)>;
/// Starts the command detached from the launcher (QProcess::startDetached): the player outlives it.
std::string launchDetached(const PlayerCommand& command);

} // namespace viscera::launcher
