#include "player_command.hpp"

#include <QCoreApplication>
#include <QProcess>
#include <QString>
#include <QStringList>

#include <memory>

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
    for (const std::string& key : settings.trustKeys)
        c.arguments.insert(c.arguments.end(), {"--trust", key});
    // TRAINEE_OPTION: the player's `--trainee ID` (the report's record of who ran the session).
    if (kPlayerHasTraineeOption && !traineeId.empty())
        c.arguments.insert(c.arguments.end(), {"--trainee", std::string(traineeId)});
    return c;
}

std::string exitReason(std::string_view text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
        text.remove_suffix(1);
    const size_t nl = text.find_last_of('\n');
    std::string_view line = nl == std::string_view::npos ? text : text.substr(nl + 1);
    constexpr std::string_view kProgram = "viscera-player: ";
    if (line.starts_with(kProgram)) line.remove_prefix(kProgram.size());
    std::string out;
    for (char c : line.substr(0, 300))
        out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? ' ' : c;
    return out;
}

std::string launchWatched(const PlayerCommand& command, ExitHandler onExit) {
    QStringList args;
    for (const std::string& a : command.arguments)
        args << QString::fromStdString(a);
    auto* process = new QProcess(QCoreApplication::instance());
    process->setProgram(QString::fromStdString(command.program));
    process->setArguments(args);
    process->setStandardOutputFile(QProcess::nullDevice());
    auto tail = std::make_shared<std::string>(); // the last 64 KiB of stderr
    QObject::connect(process, &QProcess::readyReadStandardError, process, [process, tail] {
        *tail += process->readAllStandardError().toStdString();
        if (tail->size() > 65536) tail->erase(0, tail->size() - 65536);
    });
    QObject::connect(process, &QProcess::finished, process,
                     [process, tail, onExit = std::move(onExit)](int code, QProcess::ExitStatus status) {
                         *tail += process->readAllStandardError().toStdString();
                         const int exit = status == QProcess::CrashExit ? 128 : code;
                         if (onExit) onExit(exit, exitReason(*tail));
                         process->deleteLater();
                     });
    process->start();
    if (process->waitForStarted(5000)) return {};
    process->deleteLater();
    return "could not start " + command.program + " (not installed, or not executable)";
}

} // namespace viscera::launcher
