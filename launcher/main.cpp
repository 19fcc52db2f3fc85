// viscera-launcher: the trainees' case picker. Lists the cases of the samples folder, the user's
// case folder and the folders named, and starts the chosen one in viscera-player's trainee window.
//
//   viscera-launcher [--player PATH] [--device SPEC] [--pairing-key FILE] [--trust KEY.pem] [FOLDER...]
//   viscera-launcher --list [--trust KEY.pem] [FOLDER...]
//
// Exit codes: 0 success, 1 bad input (a folder that is not one), 2 usage.
#include "case_catalog.hpp"
#include "picker_window.hpp"
#include "player_command.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/cli_main.hpp"
#include "sim/util/error.hpp"

#include <QBuffer>
#include <QCoreApplication>
#include <QDir>
#include <QFileInfo>
#include <QGuiApplication>
#include <QTimer>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace viscera;
namespace fs = std::filesystem;

void usage(std::FILE* out) {
    std::fputs("usage: viscera-launcher [--player PATH] [--device SPEC] [--pairing-key FILE] [--trust KEY.pem]\n"
               "                        [FOLDER...]\n"
               "       viscera-launcher --list [--trust KEY.pem] [FOLDER...]\n"
               "       viscera-launcher --version\n"
               "\n"
               "Lists the cases (*.vcase) of /usr/share/viscera/samples, $XDG_DATA_HOME/viscera/cases\n"
               "(~/.local/share/viscera/cases) and each FOLDER, each checked as the player would (signature\n"
               "by a trusted publisher, expiry, no older version than one run, every file's digest), and\n"
               "starts a verified one with 'viscera-player run CASE' in the trainee window. A case that\n"
               "cannot run says why on its tile; a player that stops with an error shows its reason.\n"
               "\n"
               "  --player PATH       the player to start (default: viscera-player beside this program,\n"
               "                      else from PATH)\n"
               "  --device SPEC       passed to every run: console:HOST:PORT, keyboard, replay:FILE, scripted:NAME\n"
               "  --pairing-key FILE  passed to every run (with --device console:...)\n"
               "  --trust KEY.pem     trust this publisher key too (repeatable; passed to every run)\n"
               "  --list              print the cases found, one per line (path, case id, version, title,\n"
               "                      verdict, facts), and exit (no window)\n"
               "  --screenshot FILE   open the picker, write it as PNG (atomically) and exit\n"
               "\n"
               "Keys: arrows choose, Enter starts, Esc quits; letters, digits and . _ - @ type the trainee id.\n"
               "Exit 0 ok, 1 a FOLDER that is not a folder, 2 usage or no display.\n",
               out);
}

struct Options {
    viscera::launcher::LaunchSettings launch;
    std::vector<fs::path> folders;
    bool list = false;
    std::string screenshot; ///< --screenshot: the picker as shown, then exit
};

Options parse(const sim::CliArgs& args) {
    Options o;
    bool playerGiven = false;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= args.size() || args[i + 1].empty()) throw std::invalid_argument(a + " needs a value");
            return args[++i];
        };
        if (a == "--player") {
            o.launch.player = value();
            playerGiven = true;
        } else if (a == "--device")
            o.launch.device = value();
        else if (a == "--pairing-key")
            o.launch.pairingKey = value();
        else if (a == "--trust")
            o.launch.trustKeys.push_back(fs::absolute(value()).string());
        else if (a == "--list")
            o.list = true;
        else if (a == "--screenshot") {
            o.screenshot = value();
            requireWritableFile(o.screenshot, "the screenshot");
        } else if (!a.empty() && a[0] == '-')
            throw std::invalid_argument("unknown option '" + a + "'");
        else if (!fs::is_directory(a))
            throw InputError(a + ": not a folder (name a folder that holds .vcase files)");
        else
            o.folders.push_back(fs::absolute(a));
    }
    if (!o.launch.pairingKey.empty() && o.launch.device.rfind("console:", 0) != 0)
        throw std::invalid_argument("--pairing-key is for a console link: give --device console:HOST:PORT too");
    if (!playerGiven) {
        // The player installed beside this program (the same package), else the one in PATH.
        std::error_code ec;
        const fs::path beside = fs::read_symlink("/proc/self/exe", ec).parent_path() / "viscera-player";
        if (!ec && fs::exists(beside)) o.launch.player = beside.string();
    }
    return o;
}

int listCases(const std::vector<launcher::CaseInfo>& cases) {
    for (const launcher::CaseInfo& c : cases)
        std::printf("%s\t%s\t%s\t%s\t%s\t%s\n", c.path.c_str(), c.caseId.empty() ? "-" : c.caseId.c_str(),
                    c.caseVersion.empty() ? "-" : c.caseVersion.c_str(), c.title.c_str(), c.verdict().c_str(),
                    c.description().c_str());
    if (cases.empty()) std::fprintf(stderr, "viscera-launcher: no case found\n");
    return 0;
}

int runLauncher(const sim::CliArgs& args) {
    const Options o = parse(args);
    const launcher::CaseFolders where = launcher::CaseFolders::standard(o.folders);
    const std::vector<fs::path> keys(o.launch.trustKeys.begin(), o.launch.trustKeys.end());
    launcher::VerifyCache cache(launcher::defaultVerifyCacheFile());
    const launcher::Verification check{launcher::launcherTrust(keys), &cache};
    if (o.list) return listCases(launcher::findCases(where, check));
    const char* platform = std::getenv("QT_QPA_PLATFORM");
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if (!(platform && *platform) && !(display && *display) && !(wayland && *wayland))
        return sim::cliFail("viscera-launcher", sim::kExitUsage,
                            "the launcher needs a display (DISPLAY or WAYLAND_DISPLAY); --list prints the cases");
    static int argc = 1;
    static char name[] = "viscera-launcher";
    static char* argv[] = {name, nullptr};
    // The players started are the launcher's children (their reasons come back to the window):
    // closing the window leaves a running session alone and quits when the last one has ended.
    // Declared before the application, which owns the processes, so that they outlive it.
    int running = 0;
    bool closed = false;
    QGuiApplication app(argc, argv);
    QGuiApplication::setQuitOnLastWindowClosed(false);
    const launcher::Launch launch = [&](const launcher::PlayerCommand& c, launcher::ExitHandler onExit) {
        std::string why = launcher::launchWatched(c, [&, onExit](int code, const std::string& reason) {
            --running;
            onExit(code, reason);
            if (closed && running == 0) app.quit();
        });
        if (why.empty()) ++running;
        return why;
    };
    QObject::connect(&app, &QGuiApplication::lastWindowClosed, &app, [&] {
        closed = true;
        if (running == 0) app.quit();
    });
    launcher::PickerContent content{launcher::findCases(where, check), where.folders};
    launcher::PickerWindow window(std::move(content), o.launch, launch);
    window.show();
    int status = 0;
    if (!o.screenshot.empty())
        QTimer::singleShot(300, &app, [&] { // once the window is up: the picture, then quit
            QByteArray bytes;
            QBuffer buf(&bytes);
            buf.open(QIODevice::WriteOnly);
            window.render(window.size()).save(&buf, "PNG");
            try {
                writeFileAtomic(o.screenshot, std::string_view(bytes.constData(), size_t(bytes.size())));
            } catch (const std::exception& e) {
                std::fprintf(stderr, "viscera-launcher: %s\n", e.what());
                status = 1;
            }
            app.quit();
        });
    const int rc = app.exec();
    return status ? status : rc;
}

} // namespace

int main(int argc, char** argv) {
    sim::CliProgram program;
    program.name = "viscera-launcher";
    program.version = VISCERA_VERSION;
    program.usage = usage;
    program.fallback = runLauncher;
    program.noArguments = [] { return runLauncher({}); };
    return sim::runCli(program, argc, argv);
}
