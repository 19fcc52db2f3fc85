// viscera-player: verifies and runs packaged cases (see DESIGN.md, command-line contract).
//
//   viscera-player verify <case.vcase>
//   viscera-player run <case.vcase> [--headless] [--frames N] [--device SPEC]
//                  [--report report.json] [--screenshot out.png] [--trace trace.csv] [--realtime]
//                  [--plots DIR] [--pairing-key FILE] [--trainee ID]
//   viscera-player plot <report.json> -o DIR
//
// --device: replay:<file>, scripted:<name>, console:<host:port>, keyboard (window mode only).
// Without --headless the trainee window opens (case title, instructions, timer, pedals and
// clutch, force bars, a side view of the tissue); it runs until closed, or for --frames frames
// and then writes --screenshot.
//
// Exit codes: 0 success, 1 bad input (case, arguments), 2 usage, 3 the session broke an invariant.
#include "case/case_package.hpp"
#include "case/run_state.hpp"
#include "haptics/device_spec.hpp"
#include "haptics/servo_loop.hpp"
#include "render/case_settings.hpp"
#include "render/headless.hpp"
#include "render/scene_view.hpp"
#include "render/scope_view.hpp"
#include "render/tool_meshes.hpp"
#include "runtime/report.hpp"
#include "runtime/session.hpp"
#include "runtime/soak.hpp"
#include "runtime/trust_options.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/cli_main.hpp"
#include "sim/util/error.hpp"
#include "sim/util/log.hpp"
#include "window/window_mode.hpp"
#if VISCERA_HAVE_PLOTS
#include "plots/session_plots.hpp"
#endif

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

using namespace viscera;
using sim::kExitInput, sim::kExitUsage, sim::kExitInvariant;

void usage(std::FILE* out) {
    std::fputs("usage: viscera-player verify <case.vcase> [--trust KEY.pem] [--allow-unsigned] [--state-dir DIR]\n"
               "       viscera-player run <case.vcase> [--headless] [--frames N] [--device SPEC]\n"
               "                      [--report report.json] [--screenshot out.png] [--trace trace.csv]\n"
               "                      [--realtime | --lockstep] [--servo "
               "shared|shared:US|sleep|sleep:CPU|spin:US|busy|busy:CPU]\n"
               "                      [--plots DIR] [--pairing-key FILE] [--trust KEY.pem] [--allow-unsigned]\n"
               "                      [--state-dir DIR]\n"
               "       viscera-player plot <report.json> -o DIR\n"
               "       viscera-player soak <case.vcase[@SPEC]>... [--minutes M] [--frames N] [--report soak.json]\n"
               "       SPEC: replay:<file> | scripted:<name> | console:<host:port> | keyboard\n"
               "       viscera-player --version\n",
               out);
}

constexpr const char* kVerifyHelp =
    "usage: viscera-player verify <case.vcase> [options]\n"
    "\n"
    "Checks a case package without running it, with every check 'run' makes before its first\n"
    "frame: the manifest, every file's size and checksum, the publisher's signature against the\n"
    "trusted keys, the expiry, the version against those already run, the features against those\n"
    "this player supports, the scene, the meshes, the work budget of a frame and the assembled\n"
    "world's stability. Prints the case id, version, file count, features, signer and digest.\n"
    "\n" VISCERA_PLAYER_TRUST_HELP "\n"
    "Exit 0 valid, 1 a broken, unsigned, untrusted or expired case (one line naming the file and\n"
    "the rule), 2 usage.\n";

constexpr const char* kRunHelp =
    "usage: viscera-player run <case.vcase> [options]\n"
    "\n"
    "Runs a case: the trainee window (default) or headless. Only the subsystems the case's\n"
    "manifest declares are built.\n"
    "\n"
    "  --headless            no window; runs --frames frames as fast as the physics goes\n"
    "  --frames N            frames to run (headless default 300; window: until closed)\n"
    "  --device SPEC         drive the case's tools: replay:<file.csv> | scripted:<name>\n"
    "                        (idle, press, circle, bimanual, clutch, roll) | console:<host:port>\n"
    "                        | keyboard (window only). A device that drives no tool is warned about.\n"
    "  --pairing-key FILE    console: the key shared with the console (64 hex digits); the link is\n"
    "                        authenticated with it (packaging/console-protocol.md)\n"
    "  --realtime            pace headless physics to the wall clock (console and window always are)\n"
    "  --lockstep            window: step a replay or scripted device with the physics instead of\n"
    "                        the wall clock (what happens is what the headless run shows)\n"
    "  --servo MODE          real-time servo wait: shared (default: sleeps to each deadline at real-time\n"
    "                        priority on the CPUs the physics uses) | shared:US (spins the last US) | sleep | "
    "sleep:CPU |\n"
    "                        spin:US (a CPU of its own, the physics off it) | busy | busy:CPU\n"
    "  --report FILE.json    session report (schemaVersion, frames, metrics, haptics, errors)\n"
    "  --trace FILE.csv      per-tick device force and pose trace (needs --device)\n"
    "  --screenshot FILE.png the rendered last frame (headless: EGL, window: the window)\n"
    "  --view scope|overview headless screenshot through the case's laparoscope (the default where\n"
    "                        the case has one) or framed on the whole tissue from above\n"
    "  --end-screen FILE.png window: the end-of-session screen (the verdict) as shown\n"
    "  --trainee ID          who runs the session (1-64 of A-Z a-z 0-9 . _ @ -), in the report's\n"
    "                        record for 'viscera-results add'\n"
    "  --plots DIR           session plots (PNG) and session.html, as 'viscera-player plot' "
    "makes\n" VISCERA_PLAYER_TRUST_HELP "\n"
    "Output paths are checked before the first frame. Exit 0 ok, 1 bad input or an output that\n"
    "cannot be written, 2 usage, 3 the session broke an invariant (non-finite state, energy).\n";

constexpr const char* kPlotHelp =
    "usage: viscera-player plot <report.json> -o DIR\n"
    "\n"
    "Draws a session report (viscera-player run --report) as charts: physics step time per frame\n"
    "against the real-time budget, the force on each tool, the tool paths, the task events\n"
    "(grasps, cuts, clips, punctures), energy and largest node move, and solver error against run\n"
    "time where the session sampled it. Writes step_time.png, forces.png, tool_paths.png,\n"
    "events.png, stability.png, accuracy.png (when sampled) and session.html (the figures and the\n"
    "charts in one self-contained page) into DIR, created when missing.\n"
    "Exit 0 ok, 1 a malformed report (one line naming the file, the field and the rule) or a folder\n"
    "that cannot be written, 2 usage.\n";

constexpr const char* kSoakHelp =
    "usage: viscera-player soak <case.vcase[@SPEC]>... [options]\n"
    "\n"
    "Runs the cases back to back in this one process, headless and stepped with the physics (no\n"
    "wall-clock pacing), each pass loaded afresh from its package, until the time is up. SPEC after\n"
    "'@' drives the case's tools (replay:<file.csv> or scripted:<name>). Prints a line per interval:\n"
    "frames, passes, all finite, the largest energy and whether it stays within the tolerance of\n"
    "the case's first pass, resident memory; at the end the memory growth from the 5th line.\n"
    "\n"
    "  --minutes M           wall time (default 60; decimals allowed)\n"
    "  --line-seconds S      one line per S seconds (default 60)\n"
    "  --frames N            frames per pass (default 300)\n"
    "  --energy-tolerance X  a pass's largest energy may exceed the first pass's by X (default 0.1)\n"
    "  --report FILE.json    the lines, the cases and the errors\n" VISCERA_PLAYER_TRUST_HELP "\n"
    "Exit 0 ok, 1 bad input, 2 usage, 3 a non-finite state or an energy above the bound.\n";

int fail(int code, const std::string& message) {
    return sim::cliFail("viscera-player", code, message);
}

int cmdVerify(const std::vector<std::string>& args) {
    player::TrustOptions trust;
    std::vector<std::string> operands;
    for (size_t i = 0; i < args.size(); ++i)
        if (!trust.consume(args, i)) {
            if (!args[i].empty() && args[i][0] == '-') throw std::invalid_argument("unknown option '" + args[i] + "'");
            operands.push_back(args[i]);
        }
    if (operands.size() != 1) {
        usage(stderr);
        return kExitUsage;
    }
    // Every check a run makes before its first frame: the package, its signature, expiry and
    // version, the scene, the meshes, the work budget and the assembled world (stability), so
    // that a case verify accepts also loads.
    const player::LoadedCase loaded = player::loadCase(operands[0], trust.policy(vcase::StateUse::Check));
    const vcase::Manifest& m = loaded.package->manifest();
    std::printf("%s: ok (case %s %s, %zu files, features:", operands[0].c_str(), m.caseId.c_str(),
                m.caseVersion.c_str(), m.files.size());
    for (const auto& f : m.features)
        std::printf(" %s", f.c_str());
    std::printf(")\n  package %s\n", player::packageSummary(loaded.provenance).c_str());
    return 0;
}

/// The servo's wait (--servo): shared (default), shared:US, sleep, sleep:CPU, spin:US, busy, busy:CPU.
struct ServoChoice {
    haptics::ServoWait wait = haptics::ServoWait::SleepSpin;
    int cpu = -1;
    int64_t spinNs = haptics::kSharedSpinNs;
    bool reserveCpu = false; ///< the servo owns a CPU that the physics stays off
};

ServoChoice parseServoMode(const std::string& v) {
    auto cpuOf = [&](size_t at) { // "…:CPU", one this process may run on
        const std::vector<int> allowed = haptics::allowedCpus();
        char* end = nullptr;
        const long c = std::strtol(v.c_str() + at, &end, 10);
        if (v.size() == at || *end != '\0' || std::find(allowed.begin(), allowed.end(), c) == allowed.end()) {
            std::string list;
            for (int a : allowed)
                list += (list.empty() ? "" : ", ") + std::to_string(a);
            throw std::invalid_argument("--servo '" + v + "': the CPU must be one this process may run on (" + list +
                                        ")");
        }
        return static_cast<int>(c);
    };
    auto spinOf = [&](size_t at) { // "…:US", microseconds
        char* end = nullptr;
        const long us = std::strtol(v.c_str() + at, &end, 10);
        if (v.size() == at || *end != '\0' || us < 0 || us > 1000)
            throw std::invalid_argument("--servo '" + v + "': the spin must be an integer in [0, 1000] microseconds");
        return int64_t(us) * 1000;
    };
    ServoChoice c;
    if (v == "shared") return c;
    if (v.rfind("shared:", 0) == 0) { // sleep, spin the last US microseconds, no CPU of its own
        c.spinNs = spinOf(7);
        return c;
    }
    c.reserveCpu = true;
    c.spinNs = -1; // the reserved-CPU default (ServoConfig::spin_ns)
    if (v == "sleep") return c;
    if (v.rfind("sleep:", 0) == 0) { // sleep + spin, pinned to a CPU the physics thread stays off
        c.cpu = cpuOf(6);
        return c;
    }
    if (v.rfind("spin:", 0) == 0) { // sleep, then spin the last US microseconds, on its own CPU
        c.spinNs = spinOf(5);
        return c;
    }
    c.wait = haptics::ServoWait::Busy;
    if (v == "busy") return c;
    if (v.rfind("busy:", 0) == 0) {
        c.cpu = cpuOf(5);
        return c;
    }
    throw std::invalid_argument("--servo '" + v +
                                "': expected shared, shared:US, sleep, sleep:CPU, spin:US, busy or busy:CPU");
}

struct RunArgs {
    std::optional<std::string> casePath, reportPath, screenshot, device, tracePath, plotsDir, pairingKey;
    std::string trainee;                  ///< --trainee: recorded in the report
    std::optional<std::string> endScreen; ///< --end-screen: the window's verdict screen (PNG)
    bool headless = false, realtime = false, lockstep = false, framesGiven = false;
    bool overview = false; ///< --view overview: framed on the tissue, not through the laparoscope
    ServoChoice servo;
    player::TrustOptions trust;
    int frames = 300;
};

/// A trainee id: 1–64 characters of [A-Za-z0-9._@-] (it names the trainee in the results database).
std::string traineeId(const std::string& v) {
    const bool ok = !v.empty() && v.size() <= 64 && std::all_of(v.begin(), v.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '@' || c == '-';
    });
    if (!ok) throw std::invalid_argument("--trainee '" + v + "' must be 1-64 characters of A-Z a-z 0-9 . _ @ -");
    return v;
}

RunArgs parseRunArgs(const std::vector<std::string>& args) {
    RunArgs r;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&](const char* flag) -> std::string {
            if (i + 1 >= args.size()) throw std::invalid_argument(std::string(flag) + " needs a value");
            return args[++i];
        };
        if (r.trust.consume(args, i)) continue;
        if (a == "--headless")
            r.headless = true;
        else if (a == "--frames") {
            const std::string v = value("--frames");
            char* end = nullptr;
            long n = std::strtol(v.c_str(), &end, 10);
            if (*end != '\0' || n < 1 || n > 10'000'000)
                throw std::invalid_argument("--frames '" + v + "' must be an integer in [1, 10000000]");
            r.frames = static_cast<int>(n);
            r.framesGiven = true;
        } else if (a == "--report")
            r.reportPath = value("--report");
        else if (a == "--trace")
            r.tracePath = value("--trace");
        else if (a == "--plots")
            r.plotsDir = value("--plots");
        else if (a == "--realtime")
            r.realtime = true;
        else if (a == "--lockstep")
            r.lockstep = true;
        else if (a == "--screenshot")
            r.screenshot = value("--screenshot");
        else if (a == "--view") {
            const std::string v = value("--view");
            if (v != "scope" && v != "overview")
                throw std::invalid_argument("--view '" + v + "' must be scope or overview");
            r.overview = v == "overview";
        } else if (a == "--device")
            r.device = value("--device");
        else if (a == "--pairing-key")
            r.pairingKey = value("--pairing-key");
        else if (a == "--end-screen")
            r.endScreen = value("--end-screen");
        else if (a == "--trainee")
            r.trainee = traineeId(value("--trainee"));
        else if (a == "--servo")
            r.servo = parseServoMode(value("--servo"));
        else if (!a.empty() && a[0] == '-')
            throw std::invalid_argument("unknown option '" + a + "'");
        else if (!r.casePath)
            r.casePath = a;
        else
            throw std::invalid_argument("unexpected argument '" + a + "'");
    }
    if (!r.casePath) throw std::invalid_argument("run needs a case file");
    return r;
}

/// What run refuses before any work (an exit code), else nullopt with `spec` parsed: the window
/// without a display, a bad device, options that exclude each other, and outputs that cannot be
/// written or would overwrite an input (the case, the replayed trajectory).
std::optional<int> refuseRun(const RunArgs& r, std::optional<haptics::DeviceSpec>& spec) {
    if (!r.headless) {
        if (auto why = player::windowModeUnavailable(); !why.empty()) return fail(kExitUsage, why);
        // Mesa's software rasterizer (no GPU) renders the window's view with one thread, so that
        // a render takes one core and the physics keeps the other instead of both stopping for
        // it; a GPU driver ignores it; the user's value stands. Set here, before any thread.
        setenv("LP_NUM_THREADS", "1", 0);
    }
    if (r.device) {
        spec = haptics::parseDeviceSpec(*r.device); // InputError names the spec and the rule
        if (spec->kind == haptics::DeviceSpec::Kind::Keyboard && r.headless)
            throw InputError("--device 'keyboard': the keyboard device needs the trainee window; drop --headless");
    }
    if (r.endScreen && r.headless)
        return fail(kExitUsage, "--end-screen is the trainee window's verdict screen; drop --headless");
    if (r.tracePath && !r.device)
        return fail(kExitUsage, "--trace records the device forces and poses; it needs --device");
    // Outputs are checked before the run, so that results are never lost at its end, and never
    // written over what the run reads.
    std::vector<std::filesystem::path> inputs{*r.casePath};
    if (spec && spec->kind == haptics::DeviceSpec::Kind::Replay) inputs.emplace_back(spec->argument);
    for (const auto& [path, what] :
         {std::pair{r.reportPath, "the report"}, std::pair{r.tracePath, "the trace"},
          std::pair{r.screenshot, "the screenshot"}, std::pair{r.endScreen, "the end-of-session screen"}})
        if (path) {
            requireWritableFile(*path, what);
            requireNotAnInput(*path, what, inputs);
        }
    if (r.plotsDir) {
#if VISCERA_HAVE_PLOTS
        requireWritableFolder(*r.plotsDir);
#else
        return fail(kExitUsage, "--plots: this viscera-player was built without Qt6 Gui, which draws the plots");
#endif
    }
    if (r.lockstep && r.realtime) return fail(kExitUsage, "--lockstep and --realtime exclude each other");
    if (r.lockstep && spec &&
        (spec->kind == haptics::DeviceSpec::Kind::Console || spec->kind == haptics::DeviceSpec::Kind::Keyboard))
        return fail(kExitUsage, "--lockstep: --device " + *r.device + " runs on the wall clock; drop --lockstep");
    return std::nullopt;
}

/// Renders the last frame headless (EGL; Mesa llvmpipe where there is no GPU) to `path`, with its
/// figures in result.render. The error text when it could not (a bad output, not a failed session).
std::string headlessScreenshot(player::LoadedCase& loaded, player::SessionResult& result, const std::string& path,
                               const std::string& casePath, bool noScope) {
    try {
        render::SceneView view = player::caseView(loaded);
        render::RenderSettings rs = render::defaultSettingsFor(view); // framed on the tissue
        render::applyCaseRender(rs, loaded.scene.render, casePath);
        // Instruments, probes, clips, needle and thread at the last frame; through the case's
        // laparoscope where it has one.
        const render::ToolPoses poses = render::toolPoses(*loaded.world);
        if (!noScope) render::viewThroughScope(rs, poses.scope);
        const render::ToolMeshes tools(view, poses);
        std::string why;
        auto renderer = render::HeadlessRenderer::create(rs, &why);
        if (!renderer) throw std::runtime_error("no OpenGL context: " + why);
        renderer->renderFrame(view); // first frame: shader compilation and first upload
        const render::FrameStats st = renderer->renderFrame(view);
        renderer->writePng(path);
        player::RenderFigures fig;
        fig.image = std::filesystem::absolute(path).string();
        fig.device = renderer->description();
        fig.width = rs.width;
        fig.height = rs.height;
        fig.totalMs = st.totalMs;
        fig.uploadMs = st.uploadMs;
        for (const auto& p : st.passes)
            fig.passes.push_back({p.name, p.eye, p.ms});
        result.render = std::move(fig);
        return {};
    } catch (const std::exception& e) {
        return path + ": cannot write the screenshot (" + e.what() + ")";
    }
}

/// Writes the report; when that fails at the end (a full disk), saves it under the temporary
/// folder instead. Returns where it went (empty: nowhere) and sets `error` when not at `path`.
std::string writeReport(const std::string& path, const std::string& text, std::string& error) {
    try {
        writeFileAtomic(path, text);
        return std::filesystem::absolute(path).string();
    } catch (const std::exception& e) {
        error = e.what();
    }
    std::error_code ec;
    std::filesystem::path tmp = std::filesystem::temp_directory_path(ec);
    if (ec || tmp.empty()) tmp = "/tmp"; // TMPDIR names no folder
    const std::filesystem::path fallback = tmp / ("viscera-report-" + std::to_string(::getpid()) + ".json");
    try {
        writeFileAtomic(fallback, text);
        error += "; the report was saved to " + fallback.string() + " instead";
        return fallback.string();
    } catch (const std::exception& e) {
        error += std::string("; nor could it be saved to the temporary folder (") + e.what() + ")";
        return {};
    }
}

/// The end of a run: the summary first (whatever happens to the files), then the report, trace
/// and plots, and the exit status.
int finishRun(const RunArgs& r, const player::SessionResult& result, const std::string& screenshotError) {
    std::fputs(player::summaryText(result).c_str(), stdout);
    std::fflush(stdout);
    std::vector<std::string> errors;
    if (!screenshotError.empty()) errors.push_back(screenshotError);
    // The report's text, made once: written with --report and read back by --plots.
    const std::string reportText = r.reportPath || r.plotsDir ? player::reportJson(result).dump(2) + "\n" : "";
    if (r.reportPath) {
        std::string error;
        const std::string at = writeReport(*r.reportPath, reportText, error);
        if (!at.empty()) std::printf("report        %s\n", at.c_str());
        if (!error.empty()) errors.push_back(error);
    }
    if (r.tracePath) {
        try {
            writeFileAtomic(*r.tracePath, player::traceCsv(result));
            std::printf("trace         %s\n", std::filesystem::absolute(*r.tracePath).c_str());
        } catch (const std::exception& e) {
            errors.push_back(e.what());
        }
    }
#if VISCERA_HAVE_PLOTS
    if (r.plotsDir) { // from the report's JSON, as 'plot' reads it afterwards (a non-finite figure is null)
        try {
            const player::PlotFiles files = player::writeSessionPlots(
                player::readPlotInput(nlohmann::json::parse(reportText), r.reportPath.value_or("(this session)")),
                *r.plotsDir);
            std::printf("plots         %zu charts and %s\n", files.images.size(),
                        std::filesystem::absolute(files.page).c_str());
        } catch (const std::exception& e) {
            errors.push_back(e.what());
        }
    }
#endif
    std::fflush(stdout);
    for (const std::string& e : errors)
        std::fprintf(stderr, "viscera-player: %s\n", e.c_str());
    if (!result.ok()) return kExitInvariant;
    return errors.empty() ? 0 : kExitInput;
}

int cmdRun(const std::vector<std::string>& args) {
    RunArgs r = parseRunArgs(args);
    std::optional<haptics::DeviceSpec> spec;
    if (auto refused = refuseRun(r, spec)) return *refused;
    std::unique_ptr<haptics::Device> dev;
    if (spec) {
        haptics::DeviceOpenOptions o;
        o.pairingKeyFile = r.pairingKey.value_or("");
        dev = haptics::openDevice(*spec, o);
    }
    // The window paces to the wall clock unless --lockstep asks for a replay or script stepped
    // with the physics (shown at physics speed where that is slower than real time).
    const bool rt = !r.lockstep && (r.realtime || (dev && dev->capabilities().realtime) || !r.headless);
    ServoChoice& servo = r.servo;
    if (dev && rt && servo.reserveCpu) {
        // The servo gets a CPU of its own (the highest allowed, where two or more are): this thread
        // and every thread started from here on (physics, solver workers, window) stay off it, so
        // nothing of ours waits behind the servo's spin. Not in the default shared mode, where the
        // servo preempts the physics at real-time priority for its tick.
        if (servo.cpu < 0) servo.cpu = haptics::defaultServoCpu();
        if (servo.cpu >= 0) haptics::pinCurrentThreadExcept(servo.cpu);
    }
    const vcase::TrustPolicy trust = r.trust.policy(vcase::StateUse::Record);
    player::LoadedCase loaded = player::loadCase(*r.casePath, trust);
    if (trust.stateFolder && loaded.provenance.signature == "trusted") {
        // This version ran: an older one is refused from now on. Only a trusted publisher's runs
        // count (an unsigned case allowed once must not lock the genuine one out).
        const vcase::Manifest& m = loaded.package->manifest();
        vcase::recordVersionRun(*trust.stateFolder, m.caseId, m.caseVersion);
    }
    player::RunOptions opts;
    opts.frames = r.frames;
    opts.device = dev.get();
    opts.deviceSpec = r.device.value_or("");
    opts.realtime = rt;
    opts.keepTrace = r.tracePath.has_value();
    opts.servoWait = servo.wait;
    opts.servoCpu = servo.cpu;
    opts.servoSpinNs = servo.spinNs;
    opts.trainee = r.trainee;
    player::SessionResult result;
    if (r.headless) {
        std::fprintf(
            stderr, "viscera-player: running %s for %d frames%s\n", r.casePath->c_str(), r.frames,
            dev ? (std::string(" with ") + *r.device + (opts.realtime ? " (real time)" : " (lockstep)")).c_str() : "");
        const int every = std::max(1, r.frames / 10);
        opts.progress = [every](int done, int total) {
            if (done % every == 0 || done == total)
                std::fprintf(stderr, "  frame %d/%d (%d%%)\n", done, total, 100 * done / total);
        };
        result = player::runSession(loaded, opts);
    } else {
        if (!r.framesGiven) opts.frames = 0; // until the trainee closes the window
        result = player::runWindow(loaded, opts, {r.screenshot.value_or(""), r.endScreen.value_or("")});
    }
    std::string screenshotError;
    if (r.headless && r.screenshot)
        screenshotError = headlessScreenshot(loaded, result, *r.screenshot, *r.casePath, r.overview);
    return finishRun(r, result, screenshotError);
}

double numberArg(const std::string& flag, const std::string& v, double lo, double hi) {
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(d) || d < lo || d > hi)
        throw std::invalid_argument(flag + " '" + v + "' must be a number in [" + std::to_string(lo).substr(0, 6) +
                                    ", " + std::to_string(hi).substr(0, 8) + "]");
    return d;
}

int cmdSoak(const std::vector<std::string>& args) {
    std::vector<player::SoakCase> cases;
    player::SoakOptions opt;
    opt.seconds = 3600;
    int frames = 300;
    std::optional<std::string> reportPath;
    player::TrustOptions trust;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
            return args[++i];
        };
        if (a == "--minutes")
            opt.seconds = 60 * numberArg(a, value(), 0.001, 10000);
        else if (a == "--line-seconds")
            opt.lineSeconds = numberArg(a, value(), 0.1, 3600);
        else if (a == "--frames")
            frames = static_cast<int>(numberArg(a, value(), 1, 1e7));
        else if (a == "--energy-tolerance")
            opt.energyTolerance = numberArg(a, value(), 0, 100);
        else if (a == "--report")
            reportPath = value();
        else if (trust.consume(args, i))
            continue;
        else if (!a.empty() && a[0] == '-')
            throw std::invalid_argument("unknown option '" + a + "'");
        else {
            player::SoakCase c;
            const size_t at = a.find('@');
            c.path = a.substr(0, at);
            if (at != std::string::npos) c.device = a.substr(at + 1);
            if (!c.device.empty()) {
                const haptics::DeviceSpec spec = haptics::parseDeviceSpec(c.device);
                if (spec.kind == haptics::DeviceSpec::Kind::Console || spec.kind == haptics::DeviceSpec::Kind::Keyboard)
                    throw InputError(a + ": the soak steps devices with the physics; use replay: or scripted:");
            }
            cases.push_back(std::move(c));
        }
    }
    if (cases.empty()) throw std::invalid_argument("soak needs at least one case");
    opt.trust = trust.policy(vcase::StateUse::Check);
    for (player::SoakCase& c : cases)
        c.frames = frames;
    if (reportPath) { // before the soak, which runs for minutes or hours
        requireWritableFile(*reportPath, "the soak report");
        std::vector<std::filesystem::path> inputs;
        for (const player::SoakCase& c : cases) {
            inputs.emplace_back(c.path);
            if (c.device.rfind("replay:", 0) == 0) inputs.emplace_back(c.device.substr(7));
        }
        requireNotAnInput(*reportPath, "the soak report", inputs);
    }
    std::fprintf(stderr, "viscera-player: soaking %zu case(s) for %.1f min, a line every %.0f s\n", cases.size(),
                 opt.seconds / 60, opt.lineSeconds);
    const player::SoakResult r = player::runSoak(cases, opt, [](const player::SoakLine& l) {
        std::printf("line %3d  %7.1f s  frames %6lld  passes %3d  finite %s  energy max %.4g J%s  rss %.1f MiB\n",
                    l.index, l.wall_s, static_cast<long long>(l.frames), l.passes, l.allFinite ? "yes" : "NO",
                    l.maxEnergyJ, l.energyBounded ? "" : " ABOVE THE BOUND", l.rssMiB);
        std::fflush(stdout);
    });
    if (reportPath) writeFileAtomic(*reportPath, player::soakJson(r, cases).dump(2) + "\n");
    std::printf("soak          %d passes, %lld frames; resident memory %+.2f%% from line 5 (or the first) to the "
                "last; %s\n",
                r.passes, static_cast<long long>(r.frames), 100 * r.rssGrowth(5),
                r.ok() ? "ok" : ("FAILED: " + r.errors.front()).c_str());
    for (size_t e = 1; e < r.errors.size() && e < 10; ++e)
        std::printf("              %s\n", r.errors[e].c_str());
    return r.ok() ? 0 : kExitInvariant;
}

int cmdPlot(const std::vector<std::string>& args) {
    std::optional<std::string> report, dir;
    for (size_t i = 0; i < args.size(); ++i) {
        if (args[i] == "-o" || args[i] == "--output") {
            if (i + 1 >= args.size()) throw std::invalid_argument(args[i] + " needs a folder");
            dir = args[++i];
        } else if (!args[i].empty() && args[i][0] == '-')
            throw std::invalid_argument("unknown option '" + args[i] + "'");
        else if (!report)
            report = args[i];
        else
            throw std::invalid_argument("unexpected argument '" + args[i] + "'");
    }
    if (!report) throw std::invalid_argument("plot needs a report file");
    if (!dir) throw std::invalid_argument("plot needs an output folder: -o DIR");
#if VISCERA_HAVE_PLOTS
    const player::PlotInput input = player::readPlotInputFile(*report); // a bad report creates no folder
    const player::PlotFiles files = player::writeSessionPlots(input, *dir);
    for (const auto& p : files.images)
        std::printf("%s\n", p.c_str());
    std::printf("%s\n", files.page.c_str());
    return 0;
#else
    return fail(kExitUsage, "plot: this viscera-player was built without Qt6 Gui, which draws the plots");
#endif
}

} // namespace

int main(int argc, char** argv) {
    log::setSink([](log::Level level, std::string_view msg) {
        if (level >= log::Level::Warn) std::fprintf(stderr, "viscera-player: %.*s\n", int(msg.size()), msg.data());
    });
    sim::CliProgram program;
    program.name = "viscera-player";
    program.version = VISCERA_VERSION;
    program.usage = usage;
    program.subcommands = {{"verify", cmdVerify, kVerifyHelp},
                           {"run", cmdRun, kRunHelp},
                           {"plot", cmdPlot, kPlotHelp},
                           {"soak", cmdSoak, kSoakHelp}};
    return sim::runCli(program, argc, argv);
}
