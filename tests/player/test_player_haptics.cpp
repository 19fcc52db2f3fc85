// End to end: the player with devices. Replay and scripted sessions (lockstep, repeatable), the
// console loopback over UDP with viscera-console-sim including a disconnect mid-session, the
// trainee window offscreen, and the one-line errors for bad device specs and trajectory files.
#include "player/haptic_case.hpp"
#include "support/case_signing.hpp"
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include "haptics/console_protocol.hpp"
#include "haptics/link_auth.hpp"
#include "haptics/servo_loop.hpp"
#include "haptics/trajectory.hpp"
#include "haptics/udp_socket.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

using namespace viscera;
using ::testing::HasSubstr;

namespace {

using test::Background;
using test::Scratch;

test::ProcessResult player(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_PLAYER_EXE, test::trustingSampleKey(args));
}

/// A paced (--realtime) run that checks the servo, not the machine's speed: it succeeds, or fails
/// only by the real-time verdict (exit 3, "status  FAILED: real time: ...") when the machine was
/// too busy to keep the wall clock (e.g. a parallel build); any other failure fails the test.
::testing::AssertionResult ranPaced(const test::ProcessResult& r) {
    if (r.exitCode == 0) return ::testing::AssertionSuccess();
    if (r.exitCode == 3 && r.out.find("FAILED: real time:") != std::string::npos &&
        r.out.find("invariants    all finite: yes") != std::string::npos)
        return ::testing::AssertionSuccess() << "fell behind the wall clock on a busy machine";
    return ::testing::AssertionFailure() << "exit " << r.exitCode << "\n" << r.out << r.err;
}

nlohmann::json readJson(const std::string& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

std::string readText(const std::string& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string waitForPort(const std::string& file) {
    for (int k = 0; k < 200; ++k) {
        std::ifstream in(file);
        std::string port;
        if (in >> port && !port.empty()) return port;
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    return "";
}

/// Runs the calling thread (and what it spawns meanwhile) on `cpus`; the old mask comes back
/// at the end of the scope. Nothing changes when `cpus` is empty or the system refuses.
class OnCpus {
public:
    explicit OnCpus(const std::vector<int>& cpus) {
        if (cpus.empty() || sched_getaffinity(0, sizeof(m_saved), &m_saved) != 0) return;
        cpu_set_t set;
        CPU_ZERO(&set);
        for (int c : cpus)
            CPU_SET(c, &set);
        m_active = sched_setaffinity(0, sizeof(set), &set) == 0;
    }
    ~OnCpus() {
        if (m_active) sched_setaffinity(0, sizeof(m_saved), &m_saved);
    }
    OnCpus(const OnCpus&) = delete;
    OnCpus& operator=(const OnCpus&) = delete;
    bool active() const { return m_active; }

private:
    cpu_set_t m_saved{};
    bool m_active = false;
};

/// A pairing key file made by the console simulator (as an installer would).
void writePairingKey(const std::string& path) {
    const test::ProcessResult k = test::runProcess(VISCERA_CONSOLE_SIM_EXE, {"--make-pairing-key", path});
    ASSERT_EQ(k.exitCode, 0) << k.err;
}

/// console-sim streams the bimanual script to the player (headless, real time, a probe for each
/// hand) and records the forces it gets back: s/r.json (report), s/t.csv (trace), s/sum.json
/// and s/forces.csv (console side). exitCode: the player's expected exit status (a link that
/// dropped fails the session).
void runLoopback(const Scratch& s, int frames, std::vector<std::string> simArgs, int exitCode = 0) {
    test::writeHapticCase(s / "slab.vcase", 2, VISCERA_SAMPLE_KEY);
    writePairingKey(s / "pairing.key");
    const std::vector<std::string> common = {"--listen",      "127.0.0.1:0",    "--port-file",   s / "port",
                                             "--script",      "bimanual",       "--record",      s / "forces.csv",
                                             "--summary",     s / "sum.json",   "--wait-player", "20",
                                             "--pairing-key", s / "pairing.key"};
    simArgs.insert(simArgs.end(), common.begin(), common.end());
    // The console is a machine of its own: its simulator inherits this thread's CPUs at the spawn,
    // so for that moment they leave out the CPU the player's servo will own; the player itself is
    // spawned with this thread's mask restored.
    std::optional<Background> sim;
    {
        std::vector<int> simCpus = haptics::allowedCpus();
        std::erase(simCpus, haptics::defaultServoCpu());
        const OnCpus pin(simCpus);
        sim.emplace(VISCERA_CONSOLE_SIM_EXE, simArgs, s / "sim");
    }
    const std::string port = waitForPort(s / "port");
    ASSERT_FALSE(port.empty()) << readText(s / "sim.err");
    auto r = player({"run", s / "slab.vcase", "--headless", "--frames", std::to_string(frames), "--device",
                     "console:127.0.0.1:" + port, "--pairing-key", s / "pairing.key", "--report", s / "r.json",
                     "--trace", s / "t.csv"});
    ASSERT_EQ(r.exitCode, exitCode) << r.err << r.out;
    ASSERT_EQ(sim->waitFor(), 0) << readText(s / "sim.err");
    if (exitCode != 0) ASSERT_THAT(r.out, HasSubstr("warning       haptics: the console link degraded"));
}

} // namespace

TEST(PlayerHaptics, ScriptedSessionIsRepeatableAndReportsTaskMetrics) {
    Scratch s;
    test::writeHapticCase(s / "slab.vcase", 1, VISCERA_SAMPLE_KEY);
    auto run = [&](const std::string& tag) {
        auto r = player({"run", s / "slab.vcase", "--headless", "--frames", "200", "--device", "scripted:press",
                         "--report", s / (tag + ".json"), "--trace", s / (tag + ".csv")});
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return readJson(s / (tag + ".json"));
    };
    const nlohmann::json a = run("a"), b = run("b");
    EXPECT_EQ(a["active_subsystems"], nlohmann::json({"gravity", "probe", "xpbd", "haptics"}));
    const auto& m = a["metrics"];
    for (const char* key : {"time_s", "tool_path_length_m", "device_max_force_n", "device_mean_force_n",
                            "tissue_damage_ns", "punctures", "clips"})
        EXPECT_TRUE(m.contains(key)) << key;
    EXPECT_GT(m["tool_path_length_m"].get<double>(), 0.005);
    EXPECT_GT(m["device_max_force_n"].get<double>(), 0.05) << "the probe pressed the tissue";
    EXPECT_LE(m["device_max_force_n"].get<double>(), 15.0);
    EXPECT_EQ(a["invariants"]["max_force_n"], m["device_max_force_n"]);
    const auto& h = a["haptics"];
    EXPECT_EQ(h["mode"], "lockstep");
    EXPECT_EQ(h["servo"]["ticks"].get<int>(), 3334); // 1 kHz over 200 frames of 1/60 s (0.0166667 s)
    EXPECT_LE(h["contact_model"]["max_age_over_period"].get<double>(), 1.0) << "never older than one physics step";
    EXPECT_LE(h["contact_model"]["max_steps_behind"].get<int>(), 1);
    const auto& ho = h["contact_model"]["handover"];
    EXPECT_EQ(ho["ticks_checked"].get<int>(), 3334);
    EXPECT_EQ(ho["ticks_on_older_model"].get<int>(), 0);
    EXPECT_LT(ho["max_age_over_step"].get<double>(), 1.0);
    EXPECT_EQ(ho["models_published"].get<int>(), 201); // the initial model and one per frame
    EXPECT_NEAR(ho["physics_step_ms"]["mean"].get<double>(), 1000.0 / 60, 1e-6);
    EXPECT_EQ(h["safety"]["non_finite"], 0);
    // Lockstep sessions are repeatable: same forces, same path.
    EXPECT_EQ(a["metrics"]["device_max_force_n"], b["metrics"]["device_max_force_n"]);
    EXPECT_EQ(a["metrics"]["tool_path_length_m"], b["metrics"]["tool_path_length_m"]);
    EXPECT_EQ(readText(s / "a.csv"), readText(s / "b.csv"));
    const std::string csv = readText(s / "a.csv");
    EXPECT_EQ(csv.rfind("t_s,arm,device_x", 0), 0u);
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3335);
    EXPECT_EQ(csv.find("nan"), std::string::npos);
}

/// The haptic slab case and a 3 s "press" trajectory recorded by the console simulator.
static void writeSlabAndPress(const Scratch& s) {
    test::writeHapticCase(s / "slab.vcase", 1, VISCERA_SAMPLE_KEY);
    auto w = test::runProcess(VISCERA_CONSOLE_SIM_EXE,
                              {"--write-trajectory", s / "press.csv", "--script", "press", "--duration", "3"});
    ASSERT_EQ(w.exitCode, 0) << w.err;
}

TEST(PlayerHaptics, TheConsoleSimulatorRefusesToRecordOverItsTrajectory) {
    Scratch s;
    ASSERT_NO_FATAL_FAILURE(writeSlabAndPress(s));
    const std::string before = readText(s / "press.csv");
    writePairingKey(s / "pairing.key");
    auto r = test::runProcess(VISCERA_CONSOLE_SIM_EXE,
                              {"--listen", "127.0.0.1:0", "--trajectory", s / "press.csv", "--record", s / "press.csv",
                               "--wait-player", "0.1", "--pairing-key", s / "pairing.key"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_THAT(r.err, HasSubstr((s / "press.csv") + ": cannot write the force record over the input '"));
    EXPECT_EQ(readText(s / "press.csv"), before);
}

TEST(PlayerHaptics, ReplaysARecordedTrajectory) {
    Scratch s;
    ASSERT_NO_FATAL_FAILURE(writeSlabAndPress(s));
    EXPECT_NO_THROW(haptics::Trajectory::load(s / "press.csv"));
    auto r = player({"run", s / "slab.vcase", "--headless", "--frames", "120", "--device",
                     "replay:" + (s / "press.csv"), "--report", s / "r.json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = readJson(s / "r.json");
    EXPECT_EQ(j["haptics"]["device"]["backend"], "replay");
    EXPECT_GT(j["metrics"]["device_max_force_n"].get<double>(), 0.05);
    // Real-time factor: simulated time per physics wall time, from the same step times as the
    // step statistics (whatever this machine's speed), and the summary line that says it.
    const auto& m = j["metrics"];
    const double dt = m["frame_dt_s"].get<double>(), mean = m["step_ms_mean"].get<double>();
    EXPECT_NEAR(dt, 1.0 / 60, 1e-6);
    ASSERT_GT(mean, 0.0);
    EXPECT_NEAR(m["real_time_factor"].get<double>(), dt * 1e3 / mean, 1e-9 * dt * 1e3 / mean);
    EXPECT_NEAR(m["real_time_factor_p99"].get<double>(), dt * 1e3 / m["step_ms_p99"].get<double>(),
                1e-9 * m["real_time_factor_p99"].get<double>());
    int over = 0;
    for (const auto& f : j["frames"])
        over += f["step_ms"].get<double>() > dt * 1e3 ? 1 : 0;
    EXPECT_EQ(m["frames_slower_than_real_time"].get<int>(), over);
    EXPECT_EQ(m["slower_than_real_time"].get<bool>(), m["real_time_factor"].get<double>() < 1);
    EXPECT_NE(r.out.find("real time     factor"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("PHYSICS SLOWER THAN REAL TIME") != std::string::npos, m["slower_than_real_time"].get<bool>());
}

/// The device positions of a --trace CSV, one per row, in metres rounded to 1 nm.
static std::vector<std::array<long long, 3>> tracedDevicePositions(const std::string& csv) {
    std::vector<std::array<long long, 3>> out;
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) {
        double t, x, y, z;
        int arm;
        if (std::sscanf(line.c_str(), "%lf,%d,%lf,%lf,%lf", &t, &arm, &x, &y, &z) == 5)
            out.push_back({std::llround(x * 1e9), std::llround(y * 1e9), std::llround(z * 1e9)});
    }
    return out;
}

TEST(PlayerHaptics, RealTimeReplayTakesTheLockstepRunsInput) {
    Scratch s;
    ASSERT_NO_FATAL_FAILURE(writeSlabAndPress(s));
    auto run = [&](const std::string& mode, const std::string& frames, const std::string& tag) {
        auto r =
            player({"run", s / "slab.vcase", "--headless", "--frames", frames, mode, "--device",
                    "replay:" + (s / "press.csv"), "--report", s / (tag + ".json"), "--trace", s / (tag + ".csv")});
        EXPECT_TRUE(ranPaced(r)); // the input, not the machine's speed, is checked here
        return readJson(s / (tag + ".json"));
    };
    // Lockstep runs on for 30 more frames: the real-time servo ticks on until the session stops it.
    run("--lockstep", "120", "lock");
    const auto rt = run("--realtime", "90", "rt");
    EXPECT_EQ(rt["haptics"]["mode"], "realtime");
    EXPECT_EQ(rt["haptics"]["servo"]["frames_input_missed"].get<int>(), 0);
    // Every tick of the real-time run polled the replay at a servo deadline, the instants lockstep
    // polls it at (whatever its wake-up latency), so each device position it saw is one the
    // lockstep run saw; a replay sampled at the wake-up time gives positions in between.
    const auto lock = tracedDevicePositions(readText(s / "lock.csv"));
    auto realtime = tracedDevicePositions(readText(s / "rt.csv"));
    ASSERT_GT(lock.size(), 1000u);
    ASSERT_GT(realtime.size(), 1000u);
    const std::set<std::array<long long, 3>> seen(lock.begin(), lock.end());
    ASSERT_GT(seen.size(), 500u) << "the replay moves";
    size_t outside = 0;
    for (const auto& p : realtime)
        outside += seen.count(p) == 0 ? 1 : 0;
    EXPECT_EQ(outside, 0u) << "of " << realtime.size() << " ticks";
}

// A console that never answers (nothing listens at the port) does not end "status ok": the
// session ran its frames with the tools still, and says so in a warning, the status, the report
// and the exit status.
// The console simulator's end of the link: a hello under another key opens nothing; the player's
// hello and its first command under the new key open a session and pin its address (a replayed
// hello and a second player's are refused);
// a hello that no command confirms gets a welcome and nothing else; forged, replayed and jumped
// commands and commands from another socket are refused and counted
// by reason; a 999 N command is clamped to the motors' 15 N. Without a key it does not start.
TEST(PlayerHaptics, ConsoleSimulatorKeepsItsSessionToThePlayerThatOpenedIt) {
    Scratch s;
    writePairingKey(s / "pairing.key");
    const test::ProcessResult noKey =
        test::runProcess(VISCERA_CONSOLE_SIM_EXE, {"--listen", "127.0.0.1:0", "--script", "idle", "--duration", "1"});
    EXPECT_EQ(noKey.exitCode, 2);
    EXPECT_THAT(noKey.err, HasSubstr("--pairing-key FILE is needed"));
    const haptics::LinkKey key = haptics::loadPairingKey(s / "pairing.key");
    Background sim(VISCERA_CONSOLE_SIM_EXE,
                   {"--listen", "127.0.0.1:0", "--port-file", s / "port", "--script", "idle", "--duration", "1.5",
                    "--summary", s / "sum.json", "--wait-player", "20", "--pairing-key", s / "pairing.key"},
                   s / "sim");
    const std::string port = waitForPort(s / "port");
    ASSERT_FALSE(port.empty()) << readText(s / "sim.err");
    const haptics::Endpoint console = haptics::parseEndpoint("127.0.0.1:" + port, "test", true);
    haptics::UdpSocket me(haptics::parseEndpoint("127.0.0.1:0", "test", true));
    haptics::UdpSocket other(haptics::parseEndpoint("127.0.0.1:0", "test", true));
    const haptics::LinkMac pairing(key), stranger(haptics::randomKey());
    std::vector<uint8_t> b(haptics::kMaxPacketSize);
    auto send = [&](haptics::UdpSocket& from, const auto& packet, const haptics::LinkMac& mac) {
        b.assign(haptics::kMaxPacketSize, 0);
        b.resize(haptics::encode(packet, b.data(), b.size(), mac));
        ASSERT_TRUE(from.sendTo(b.data(), b.size(), console));
    };
    haptics::HelloPacket h0; // a valid hello that no command ever confirms: a welcome, no stream
    h0.client = haptics::randomNonce();
    send(other, h0, pairing);
    haptics::HelloPacket h;
    h.client = haptics::randomNonce();
    send(me, h, stranger); // another pairing key: no session
    send(me, h, pairing);
    const std::vector<uint8_t> hello = b;
    haptics::WelcomePacket w;
    bool welcomed = false;
    for (int k = 0; k < 200 && !welcomed; ++k) {
        ASSERT_TRUE(me.wait(2000));
        uint8_t in[haptics::kMaxPacketSize];
        const long n = me.receive(in, sizeof in, nullptr);
        welcomed = n > 0 && haptics::decode(in, size_t(n), w, pairing) == haptics::DecodeError::None;
    }
    ASSERT_TRUE(welcomed);
    EXPECT_EQ(w.client, h.client);
    const haptics::LinkMac session(haptics::sessionKey(key, h.client, w.server));
    haptics::CommandPacket c;
    c.sequence = 10;
    c.arm[0].servo_cf.force = haptics::Vec3(0, 0, 999); // beyond the motors; confirms the session
    send(me, c, session);
    const std::vector<uint8_t> first = b;
    ASSERT_TRUE(me.sendTo(hello.data(), hello.size(), console)); // replayed hello
    haptics::HelloPacket h2;
    h2.client = haptics::randomNonce();
    send(other, h2, pairing); // a second player while the session lives
    c.sequence = 11;
    c.arm[0].servo_cf.force = haptics::Vec3(0, 0, 1);
    send(me, c, session);
    ASSERT_TRUE(me.sendTo(first.data(), first.size(), console)); // replayed
    c.sequence = 11 + 5000;
    send(me, c, session); // jumped
    c.sequence = 12;
    send(me, c, stranger);   // forged
    send(other, c, session); // from another socket
    ASSERT_EQ(sim.waitFor(), 0) << readText(s / "sim.err");
    int toOther = 0; // the unconfirmed hello's welcome only: no state went to that address
    uint8_t in[haptics::kMaxPacketSize];
    for (long n; (n = other.receive(in, sizeof in, nullptr)) >= 0; ++toOther)
        EXPECT_EQ(haptics::peekType(in, size_t(n)), uint16_t(haptics::PacketType::Welcome));
    EXPECT_EQ(toOther, 1);
    const auto sum = readJson(s / "sum.json");
    EXPECT_EQ(sum["handshakes"], 1);
    EXPECT_EQ(sum["commands_received"], 2);
    EXPECT_EQ(sum["commands_clamped"], 1);
    EXPECT_LE(sum["max_force_n"].get<double>(), 15.0 + 1e-9);
    EXPECT_GE(sum["max_force_n"].get<double>(), 15.0 - 1e-3);
    const auto& r = sum["rejected"];
    EXPECT_EQ(r.value("auth", 0), 2) << r.dump(); // the stranger's hello and the forged command
    EXPECT_EQ(r.value("replayed_hello", 0), 1) << r.dump();
    EXPECT_EQ(r.value("peer", 0), 2) << r.dump();
    EXPECT_EQ(r.value("order", 0), 1) << r.dump();
    EXPECT_EQ(r.value("jump", 0), 1) << r.dump();
}

TEST(PlayerHaptics, ConsoleThatNeverAnswersFailsTheSession) {
    Scratch s;
    test::writeHapticCase(s / "slab.vcase", 1, VISCERA_SAMPLE_KEY);
    writePairingKey(s / "pairing.key");
    auto r = player({"run", s / "slab.vcase", "--headless", "--frames", "30", "--device", "console:127.0.0.1:9",
                     "--pairing-key", s / "pairing.key", "--report", s / "r.json"});
    EXPECT_EQ(r.exitCode, 3) << r.out << r.err;
    EXPECT_THAT(r.out, HasSubstr("warning       haptics: --device console:127.0.0.1:9: the console never answered (0 "
                                 "valid state packets in "));
    EXPECT_THAT(r.out, HasSubstr("status        FAILED: haptics: --device console:127.0.0.1:9: the console never"));
    const auto j = readJson(s / "r.json");
    EXPECT_EQ(j["haptics"]["link"]["received"], 0);
    ASSERT_EQ(j["errors"].size(), 1u);
    EXPECT_THAT(j["errors"][0].get<std::string>(), HasSubstr("never answered"));
}

TEST(PlayerHaptics, BadDeviceSpecsAndTrajectoriesGiveOneLineErrors) {
    Scratch s;
    test::writeHapticCase(s / "slab.vcase", 1, VISCERA_SAMPLE_KEY);
    std::ofstream(s / "bad.csv")
        << "# viscera-trajectory 1\nt,arm,x,y,z,qw,qx,qy,qz,grip,buttons,pedals\n0,0,0,0,0,1,0,0,0,0,0,99\n";
    struct Bad {
        std::string spec, rule;
        int code;
    };
    const std::vector<Bad> bad = {{"joystick", "unknown device backend", 1},
                                  {"console:localhost", "must be host:port", 1},
                                  {"replay:" + (s / "missing.csv"), "missing.csv", 1},
                                  {"replay:" + (s / "bad.csv"), "bad.csv: line 3: field 'pedals'", 1},
                                  {"scripted:nope", "unknown script", 1},
                                  {"keyboard", "needs the trainee window", 1}};
    for (const Bad& b : bad) {
        auto r = player({"run", s / "slab.vcase", "--headless", "--frames", "5", "--device", b.spec});
        EXPECT_EQ(r.exitCode, b.code) << b.spec << ": " << r.err;
        EXPECT_THAT(r.err, HasSubstr(b.rule)) << b.spec;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    auto t = player({"run", s / "slab.vcase", "--headless", "--trace", s / "t.csv"});
    EXPECT_EQ(t.exitCode, 2);
    EXPECT_THAT(t.err, HasSubstr("--trace records the device forces"));
}

TEST(PlayerHaptics, ConsoleLoopbackWithADisconnectMidSession) {
    Scratch s;
    // The console streams 3.5 s of the bimanual script, silent from 1.0 s to 1.6 s.
    // The dropped link fails the session (a warning, status FAILED, exit 3) after it ran on.
    ASSERT_NO_FATAL_FAILURE(runLoopback(s, 180, {"--duration", "3.5", "--pause-at", "1.0", "--pause-for", "0.6"}, 3));
    const auto j = readJson(s / "r.json");
    const auto& h = j["haptics"];
    EXPECT_EQ(h["mode"], "realtime");
    EXPECT_EQ(h["device"]["arms"], 2);
    EXPECT_EQ(h["tools"][0]["arm"], 0) << "the left-hand probe follows the left master";
    EXPECT_EQ(h["tools"][1]["arm"], 1) << "the right-hand probe follows the right master";
    EXPECT_GE(h["link"]["disconnects"].get<int>(), 1);
    EXPECT_GE(h["link"]["reconnects"].get<int>(), 1);
    EXPECT_GT(h["safety"]["disconnected"].get<int>(), 0);
    EXPECT_GT(h["servo"]["ticks"].get<int>(), 1000);
    EXPECT_LE(h["contact_model"]["max_steps_behind"].get<int>(), 1);
    // Every tick used the newest model the physics thread had published (its own log says when).
    const auto& ho = h["contact_model"]["handover"];
    EXPECT_EQ(ho["ticks_checked"], h["servo"]["ticks"]);
    EXPECT_EQ(ho["ticks_on_older_model"].get<int>(), 0);
    EXPECT_LE(ho["max_age_over_step"].get<double>(), 1.0);
    EXPECT_EQ(ho["models_published"].get<int>(), 181);
    // The default servo wait shares the CPUs with the physics (--servo shared): not pinned, the
    // physics keeps every CPU, the servo sleeps to each deadline without spinning.
    const std::vector<int> allowed = haptics::allowedCpus();
    const auto& servo = h["servo"];
    EXPECT_EQ(servo["cpu"].get<int>(), -1);
    EXPECT_EQ(servo["physics_cpus"].get<std::vector<int>>(), allowed);
    EXPECT_EQ(servo["spin_us"].get<int>(), 0);
    EXPECT_FALSE(servo["physics_realtime_priority"].get<bool>()) << "sharing: the physics stays SCHED_OTHER";
    EXPECT_TRUE(servo.contains("frame_lag_ms"));
    EXPECT_TRUE(servo.contains("frames_late"));
    EXPECT_TRUE(j["invariants"]["all_finite"].get<bool>());
    // The player kept running through the gap and forces came back to the console afterwards.
    const auto sum = readJson(s / "sum.json");
    EXPECT_GT(sum["commands_received"].get<int>(), 1000);
    EXPECT_EQ(sum["commands_non_finite"], 0);
    EXPECT_EQ(sum["paused_nonzero_after_timeout"], 0) << "force zeroed while the console was silent";
    EXPECT_LE(sum["max_force_n"].get<double>(), 15.0);
    const std::string forces = readText(s / "forces.csv");
    EXPECT_EQ(forces.find("nan"), std::string::npos);
    // Non-zero forces after the reconnection (t > 1.6 s): the left arm is still pressing.
    bool after = false;
    std::istringstream lines(forces);
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) {
        double t, f[6];
        unsigned seq, echo, flags;
        int paused;
        if (std::sscanf(line.c_str(), "%lf,%u,%u,%u,%d,%lf,%lf,%lf,%lf,%lf,%lf", &t, &seq, &echo, &flags, &paused,
                        &f[0], &f[1], &f[2], &f[3], &f[4], &f[5]) == 11 &&
            t > 1.7 && (std::abs(f[2]) > 0.01 || std::abs(f[5]) > 0.01))
            after = true;
    }
    EXPECT_TRUE(after) << "forces resume after the reconnection\nconsole: " << readText(s / "sum.json")
                       << "player link: " << h["link"].dump() << "\nsafety: " << h["safety"].dump()
                       << "\nmetrics: " << j["metrics"].dump();
}

TEST(PlayerHaptics, ConsoleStreamsUntilThePlayerStops) {
    // --until-player-stops: the console streams as long as the player talks to it (a player behind
    // the wall clock gets its input to its last frame), bounded by --duration, and then stops.
    Scratch s;
    ASSERT_NO_FATAL_FAILURE(runLoopback(s, 90, {"--loop", "--duration", "60", "--until-player-stops"}));
    const auto j = readJson(s / "r.json");
    EXPECT_EQ(j["haptics"]["link"]["disconnects"].get<int>(), 0) << "the console streamed to the last frame";
    const auto sum = readJson(s / "sum.json");
    const double streamed = sum["duration_s"].get<double>();
    EXPECT_GE(streamed, 90.0 / 60 - 0.05) << "it streamed through the whole session";
    EXPECT_LT(streamed, 59.0) << "it stopped with the player, not at the --duration bound";
    EXPECT_GT(sum["commands_received"].get<int>(), 1000);
}

TEST(PlayerHaptics, SixtySecondConsoleLoopback) {
    // The acceptance loopback over 60 s (scripts/haptics-loopback.sh runs the same and prints a
    // summary). Checked: every servo tick used the newest contact model the physics had published,
    // the forces stayed finite and within the case maximum on both ends, no packet was rejected.
    // The timing figures are recorded (test properties), not asserted: this machine is shared.
    Scratch s;
    ASSERT_NO_FATAL_FAILURE(runLoopback(s, 3600, {"--loop", "--duration", "61"}));
    const auto j = readJson(s / "r.json");
    const auto& h = j["haptics"];
    const auto& servo = h["servo"];
    const auto& ho = h["contact_model"]["handover"];
    EXPECT_GT(servo["ticks"].get<int>(), 0);
    EXPECT_EQ(ho["ticks_checked"], servo["ticks"]);
    EXPECT_EQ(ho["ticks_on_older_model"].get<int>(), 0);
    EXPECT_LE(ho["max_age_over_step"].get<double>(), 1.0);
    EXPECT_EQ(ho["models_published"].get<int>(), 3601);
    EXPECT_EQ(h["safety"]["non_finite"], 0);
    for (const char* k : {"rejected_malformed", "rejected_version", "rejected_auth", "rejected_order", "rejected_jump",
                          "rejected_peer", "send_errors"})
        EXPECT_EQ(h["link"][k], 0) << k;
    EXPECT_TRUE(j["invariants"]["all_finite"].get<bool>());
    EXPECT_LE(j["metrics"]["device_max_force_n"].get<double>(), h["case_max_force_n"].get<double>());
    const auto sum = readJson(s / "sum.json");
    EXPECT_GT(sum["commands_received"].get<int>(), 0);
    EXPECT_EQ(sum["commands_non_finite"], 0);
    EXPECT_LE(sum["max_force_n"].get<double>(), 15.0);
    EXPECT_EQ(readText(s / "forces.csv").find("nan"), std::string::npos);
    auto us = [&](const nlohmann::json& d, const char* k) { return std::to_string(d[k].get<double>()); };
    ::testing::Test::RecordProperty("servo_ticks", std::to_string(servo["ticks"].get<int>()));
    ::testing::Test::RecordProperty("period_mean_us", us(servo["period_us"], "mean"));
    ::testing::Test::RecordProperty("jitter_p99_us", us(servo["jitter_us"], "p99"));
    ::testing::Test::RecordProperty("jitter_max_us", us(servo["jitter_us"], "max"));
    ::testing::Test::RecordProperty("contact_age_max_ms", us(h["contact_model"]["age_ms"], "max"));
    ::testing::Test::RecordProperty("physics_step_max_ms", us(ho["physics_step_ms"], "max"));
    std::printf("servo %d ticks, period mean %.1f us, jitter p99 %.0f us, max %.0f us; contact age max %.2f ms, "
                "physics step max %.2f ms, %d ticks on an older model\n",
                servo["ticks"].get<int>(), servo["period_us"]["mean"].get<double>(),
                servo["jitter_us"]["p99"].get<double>(), servo["jitter_us"]["max"].get<double>(),
                h["contact_model"]["age_ms"]["max"].get<double>(), ho["physics_step_ms"]["max"].get<double>(),
                ho["ticks_on_older_model"].get<int>());
}

TEST(PlayerHaptics, TraineeWindowRunsOffscreenAndWritesAScreenshot) {
    Scratch s;
    test::writeHapticCase(s / "slab.vcase", 1, VISCERA_SAMPLE_KEY);
    ::setenv("QT_QPA_PLATFORM", "offscreen", 1);
    auto r = player({"run", s / "slab.vcase", "--frames", "30", "--device", "scripted:press", "--screenshot",
                     s / "shot.png", "--report", s / "r.json"});
    ::unsetenv("QT_QPA_PLATFORM");
    if (r.exitCode == 2 && r.err.find("Qt6 Gui") != std::string::npos) GTEST_SKIP() << "player built without Qt6 Gui";
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string png = readText(s / "shot.png");
    ASSERT_GT(png.size(), 1000u);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    EXPECT_EQ(readJson(s / "r.json")["frames"].size(), 30u);
    // With --headless, --screenshot renders the 3D view instead (tests/player/player_screenshot_gl_test.cpp).
}

TEST(PlayerHaptics, BusyServoWaitPinsTheServoThreadAndReportsItsPriority) {
    Scratch s;
    test::writeHapticCase(s / "slab.vcase", 1, VISCERA_SAMPLE_KEY);
    auto r = player({"run", s / "slab.vcase", "--headless", "--frames", "60", "--device", "scripted:press",
                     "--realtime", "--servo", "busy:0", "--report", s / "r.json"});
    ASSERT_TRUE(ranPaced(r));
    const auto servo = readJson(s / "r.json")["haptics"]["servo"];
    EXPECT_EQ(servo["wait"], "busy");
    EXPECT_EQ(servo["cpu"], 0);
    EXPECT_GT(servo["ticks"].get<int>(), 500);
    // A real-time spinner is only used where the kernel does not throttle real-time tasks; the
    // report says why when the servo thread did not get SCHED_FIFO.
    if (!servo["realtime_priority"].get<bool>()) {
        EXPECT_TRUE(servo.contains("priority_note"));
    }
    std::ifstream rt("/proc/sys/kernel/sched_rt_runtime_us");
    long runtime = 0;
    if (rt >> runtime && runtime >= 0) {
        EXPECT_FALSE(servo["realtime_priority"].get<bool>()) << "busy + SCHED_FIFO would be throttled";
        EXPECT_THAT(servo["priority_note"].get<std::string>(), HasSubstr("sched_rt_runtime_us"));
    }
    auto sleep = player({"run", s / "slab.vcase", "--headless", "--frames", "10", "--device", "scripted:press",
                         "--realtime", "--report", s / "r2.json"});
    ASSERT_TRUE(ranPaced(sleep));
    EXPECT_EQ(readJson(s / "r2.json")["haptics"]["servo"]["wait"], "sleep");
    EXPECT_EQ(readJson(s / "r2.json")["haptics"]["servo"]["cpu"], -1) << "shared by default";
    auto spin = player({"run", s / "slab.vcase", "--headless", "--frames", "10", "--device", "scripted:press",
                        "--realtime", "--servo", "spin:900", "--report", s / "r3.json"});
    ASSERT_TRUE(ranPaced(spin));
    EXPECT_EQ(readJson(s / "r3.json")["haptics"]["servo"]["spin_us"], 900);
    auto shared = player({"run", s / "slab.vcase", "--headless", "--frames", "10", "--device", "scripted:press",
                          "--realtime", "--servo", "shared:30", "--report", s / "r5.json"});
    ASSERT_TRUE(ranPaced(shared));
    EXPECT_EQ(readJson(s / "r5.json")["haptics"]["servo"]["spin_us"], 30);
    EXPECT_EQ(readJson(s / "r5.json")["haptics"]["servo"]["cpu"], -1);
    // "sleep" reserves the highest CPU for the servo; the physics keeps the others.
    auto reserved = player({"run", s / "slab.vcase", "--headless", "--frames", "10", "--device", "scripted:press",
                            "--realtime", "--servo", "sleep", "--report", s / "r6.json"});
    ASSERT_TRUE(ranPaced(reserved));
    const auto rs = readJson(s / "r6.json")["haptics"]["servo"];
    const std::vector<int> cpus = haptics::allowedCpus();
    if (cpus.size() >= 2) {
        EXPECT_EQ(rs["cpu"].get<int>(), cpus.back());
        EXPECT_EQ(rs["physics_cpus"].get<std::vector<int>>(), std::vector<int>(cpus.begin(), cpus.end() - 1));
        EXPECT_EQ(rs["spin_us"].get<int>(), 940);
    }
    // A mask set from outside (taskset, cpusets) is respected: started on one CPU, the player
    // shares it with the servo instead of pinning anything elsewhere.
    const std::vector<int> allowed = haptics::allowedCpus();
    ASSERT_FALSE(allowed.empty());
    test::ProcessResult masked, outside;
    {
        const OnCpus pin({allowed.front()});
        ASSERT_TRUE(pin.active());
        masked = player({"run", s / "slab.vcase", "--headless", "--frames", "10", "--device", "scripted:press",
                         "--realtime", "--report", s / "r4.json"});
        outside = player({"run", s / "slab.vcase", "--headless", "--frames", "1", "--device", "scripted:press",
                          "--realtime", "--servo", "sleep:" + std::to_string(allowed.back() + 1)});
    }
    ASSERT_TRUE(ranPaced(masked));
    const auto m = readJson(s / "r4.json")["haptics"]["servo"];
    EXPECT_EQ(m["cpu"], -1);
    EXPECT_EQ(m["physics_cpus"].get<std::vector<int>>(), std::vector<int>{allowed.front()});
    EXPECT_EQ(outside.exitCode, 2);
    EXPECT_THAT(outside.err,
                HasSubstr("the CPU must be one this process may run on (" + std::to_string(allowed.front()) + ")"));
    for (const char* bad : {"busy:", "busy:x", "busy:-1", "busy:4096", "sleep:", "sleep:4096", "spin",
                            "spin:", "spin:2000", "spin:-5", "shared:", "shared:x", "shared:2000", "sharedx"}) {
        auto b = player({"run", s / "slab.vcase", "--headless", "--frames", "1", "--servo", bad});
        EXPECT_EQ(b.exitCode, 2) << bad;
        EXPECT_THAT(b.err, HasSubstr("--servo")) << bad;
    }
}

// Every program says its version, and the player's and console simulator's man pages document
// every subcommand and --version their usage lists (the soak was missing from the man page).
TEST(PlayerHaptics, EveryProgramSaysItsVersionAndItsManPageListsEveryCommand) {
    const auto sim = test::runProcess(VISCERA_CONSOLE_SIM_EXE, {"--version"});
    EXPECT_EQ(sim.exitCode, 0) << sim.err;
    EXPECT_EQ(sim.out, std::string("viscera-console-sim ") + VISCERA_VERSION + "\n");
    const auto pl = test::runProcess(VISCERA_PLAYER_EXE, {"--version"});
    EXPECT_EQ(pl.exitCode, 0) << pl.err;
    EXPECT_EQ(pl.out, std::string("viscera-player ") + VISCERA_VERSION + "\n");
    const std::string man = readText(std::filesystem::path(VISCERA_SOURCE_DIR) / "packaging/man/viscera-player.1");
    for (const char* cmd : {"verify", "run", "plot", "soak"}) {
        EXPECT_THAT(man, HasSubstr(std::string(".B viscera-player ") + cmd + "\n")) << cmd << " in the synopsis";
        EXPECT_THAT(man, HasSubstr(std::string(".TP\n.B ") + cmd + "\n")) << cmd << " under COMMANDS";
    }
    EXPECT_THAT(man, HasSubstr(".B viscera-player \\-\\-version"));
    const std::string simMan =
        readText(std::filesystem::path(VISCERA_SOURCE_DIR) / "packaging/man/viscera-console-sim.1");
    EXPECT_THAT(simMan, HasSubstr(".B viscera-console-sim \\-\\-version"));
    const auto help = test::runProcess(VISCERA_CONSOLE_SIM_EXE, {"--help"});
    EXPECT_THAT(help.out, HasSubstr("viscera-console-sim --version"));
}
