#include "player_command.hpp"

#include <QProcess>
#include <QString>
#include <QStringList>

namespace viscera::launcher {

std::string PlayerCommand::display() const {
    std::string out;
    for (size_t i = 0; i <= arguments.size(); ++i) {
        const std::string& w = i == 0 ? program : arguments[i - 1];
        const bool quote = w.empty() || w.find_first_of(" \t'\"\\$") != std::string::npos;
        out += (i ? " " : "") + (quote ? "'" + w + "'" : w);
    }
    return out;
}

bool isTraineeIdCharacter(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-' || c == '@';
}

std::string traineeIdProblem(std::string_view id) {
    if (id.empty()) return "the trainee id is empty";
    if (id.size() > kMaxTraineeIdLength)
        return "the trainee id has " + std::to_string(id.size()) + " characters, more than " +
               std::to_string(kMaxTraineeIdLength);
    for (char c : id)
        if (!isTraineeIdCharacter(c)) return "the trainee id may hold only letters, digits and . _ - @";
    return {};
}

PlayerCommand playerCommand(const LaunchSettings& settings, const std::filesystem::path& caseFile,
                            std::string_view traineeId) {
    PlayerCommand c;
    c.program = settings.player;
    c.arguments = {"run", caseFile.string()}; // no --headless: the trainee window
    if (!settings.device.empty()) c.arguments.insert(c.arguments.end(), {"--device", settings.device});
    if (!settings.pairingKey.empty()) c.arguments.insert(c.arguments.end(), {"--pairing-key", settings.pairingKey});
    // TRAINEE_OPTION: the player's `--trainee ID` (the report's record of who ran the session).
    if (kPlayerHasTraineeOption && !traineeId.empty())
        c.arguments.insert(c.arguments.end(), {"--trainee", std::string(traineeId)});
    return c;
}

std::string launchDetached(const PlayerCommand& command) {
    QStringList args;
    for (const std::string& a : command.arguments)
        args << QString::fromStdString(a);
    if (QProcess::startDetached(QString::fromStdString(command.program), args)) return {};
    return "could not start " + command.program + " (not installed, or not executable)";
}

} // namespace viscera::launcher
