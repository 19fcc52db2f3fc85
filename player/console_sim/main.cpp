// viscera-console-sim: a stand-in for the bimanual console (2 × 7-DOF masters with grip, five
// pedals, [B §4]). It speaks the console protocol (packaging/console-protocol.md) over UDP:
// replays a recorded trajectory (or a scripted motion) as state packets at 1 kHz to the player
// that opened a session with it (a hello under the shared pairing key), and records every force
// command it receives, clamped to its motors' 15 N.
//
//   viscera-console-sim --listen HOST:PORT --pairing-key FILE (--trajectory FILE | --script NAME)
//                       [--duration S] [--rate HZ] [--loop] [--record forces.csv]
//                       [--summary summary.json] [--port-file FILE] [--pause-at S --pause-for S]
//                       [--wait-player S] [--until-player-stops]
//   viscera-console-sim --write-trajectory OUT.csv --script NAME --duration S [--rate HZ]
//   viscera-console-sim --make-pairing-key FILE
//
// The session: a hello from any address is answered while no session is live (no valid command
// for 1 s), or from the session's own address; the session opens (or switches) when a command from
// that address verifies under the key of that handshake, and the console then reads commands from
// that address only. Hellos are answered once (a replayed nonce is refused); commands must carry
// the session's MAC and a newer sequence no more than kMaxSequenceJump ahead. Refusals are counted
// by reason in the summary.
//
// --until-player-stops streams like the real console until the player has sent nothing for 1 s
// (its session ended), --duration bounding the whole run: a player that falls behind the wall
// clock gets its input to the end instead of a disconnection the console made.
// --pause-at/--pause-for simulate a disconnection: no state is sent during the pause (commands
// are still recorded, dated by their arrival in the kernel queue; a command with force more than
// 250 ms after the last state actually sent counts as paused_nonzero_after_timeout). Exit codes: 0 done, 1 bad input, 2
// usage, 3 no player contacted it.
#include "haptics/clock.hpp"
#include "haptics/console_protocol.hpp"
#include "haptics/link_auth.hpp"
#include "haptics/scripted_device.hpp"
#include "haptics/trajectory.hpp"
#include "haptics/udp_socket.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/cli_main.hpp"
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <time.h>
#include <vector>

namespace {

using namespace viscera;
using namespace viscera::haptics;

struct Options {
    std::string listen = "127.0.0.1:7400";
    std::optional<std::string> trajectory, script, record, summary, portFile, writeTrajectory, pairingKey,
        makePairingKey;
    double duration = -1, rate = 1000, pauseAt = -1, pauseFor = 0, waitPlayer = 30;
    bool loop = false;
    bool untilPlayerStops = false;
};

struct Received {
    double t = 0;
    bool paused = false;
    CommandPacket cmd;
};

double number(const std::string& flag, const std::string& v, double lo, double hi) {
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(x) || x < lo || x > hi)
        throw std::invalid_argument(flag + " '" + v + "' must be a number in [" + std::to_string(lo) + ", " +
                                    std::to_string(hi) + "]");
    return x;
}

Options parse(const std::vector<std::string>& args) {
    Options o;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
            return args[++i];
        };
        if (a == "--listen")
            o.listen = value();
        else if (a == "--trajectory")
            o.trajectory = value();
        else if (a == "--script")
            o.script = value();
        else if (a == "--record")
            o.record = value();
        else if (a == "--summary")
            o.summary = value();
        else if (a == "--port-file")
            o.portFile = value();
        else if (a == "--write-trajectory")
            o.writeTrajectory = value();
        else if (a == "--pairing-key")
            o.pairingKey = value();
        else if (a == "--make-pairing-key")
            o.makePairingKey = value();
        else if (a == "--duration")
            o.duration = number(a, value(), 0.001, 86400);
        else if (a == "--rate")
            o.rate = number(a, value(), 1, 10000);
        else if (a == "--pause-at")
            o.pauseAt = number(a, value(), 0, 86400);
        else if (a == "--pause-for")
            o.pauseFor = number(a, value(), 0, 86400);
        else if (a == "--wait-player")
            o.waitPlayer = number(a, value(), 0.1, 3600);
        else if (a == "--loop")
            o.loop = true;
        else if (a == "--until-player-stops")
            o.untilPlayerStops = true;
        else
            throw std::invalid_argument("unknown option '" + a + "'");
    }
    if (o.makePairingKey) return o;
    if (o.trajectory.has_value() == o.script.has_value())
        throw std::invalid_argument("give exactly one of --trajectory FILE or --script NAME");
    if (o.writeTrajectory && (!o.script || o.duration <= 0))
        throw std::invalid_argument("--write-trajectory needs --script NAME and --duration S");
    return o;
}

void sleepUntil(int64_t t) {
    timespec ts{};
    ts.tv_sec = t / 1'000'000'000;
    ts.tv_nsec = t % 1'000'000'000;
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
}

/// The motion source: a trajectory file or a scripted device, sampled at time t (s).
class Source {
public:
    explicit Source(const Options& o) : m_loop(o.loop) {
        if (o.trajectory)
            m_traj = Trajectory::load(*o.trajectory);
        else
            m_script = std::make_unique<ScriptedDevice>(*o.script);
    }
    void sample(double t, DeviceState& s) {
        if (m_traj)
            m_traj->sampleInto(t, m_loop, s);
        else
            m_script->poll(int64_t(std::llround(t * 1e9)), s);
    }
    int arms() const { return m_traj ? std::max(1, m_traj->arms()) : m_script->capabilities().arms; }
    double duration() const { return m_traj ? m_traj->duration() : 0; }

private:
    bool m_loop;
    std::optional<Trajectory> m_traj;
    std::unique_ptr<ScriptedDevice> m_script;
};

/// The console's end of the session (packaging/console-protocol.md, version 2): who it talks to,
/// under which key, and what it refused. A hello only proposes a session (answered with a
/// welcome); the session switches when a command verifies under its key (key confirmation), so a
/// replayed hello can neither re-key the live session nor pin another address.
struct Link {
    static constexpr int64_t kSessionIdleNs = 1'000'000'000; ///< no valid command this long: a new peer may open one
    static constexpr size_t kMaxPending = 4;                 ///< proposed sessions kept (the newest)
    explicit Link(const LinkKey& key) : pairing(key) {}

    struct Proposal {
        Endpoint from;
        LinkKey key;
    };
    LinkMac pairing, session, candidate;
    Endpoint player;
    bool havePlayer = false, commanded = false, seqValid = false;
    uint32_t lastSeq = 0, sendSeq = 0;
    int64_t lastHeard = 0;
    std::vector<Nonce> nonces;       ///< hellos already answered (a replayed hello is refused)
    std::vector<Proposal> proposals; ///< welcomed, not yet confirmed by a command
    std::map<std::string, uint64_t> rejected;
    uint64_t handshakes = 0, clamped = 0;

    bool refuse(const char* reason) {
        ++rejected[reason];
        return false;
    }
    bool refuse(DecodeError e) {
        return refuse(e == DecodeError::BadVersion ? "version" : e == DecodeError::BadMac ? "auth" : "malformed");
    }

    /// One datagram: a hello (a proposal, answered with a welcome) or a command (into c,
    /// commanded = true). False when refused (counted by reason).
    bool take(const uint8_t* data, size_t size, const Endpoint& from, int64_t arrived, UdpSocket& sock,
              CommandPacket& c) {
        commanded = false;
        if (peekType(data, size) == static_cast<uint16_t>(PacketType::Hello))
            return hello(data, size, from, arrived, sock);
        DecodeError e = DecodeError::BadMac;
        if (havePlayer && from == player) e = decode(data, size, c, session);
        if (e == DecodeError::BadMac && !confirm(data, size, from, c)) {
            if (!havePlayer) return refuse("auth"); // no session: nothing can carry its MAC
            if (!(from == player)) return refuse("peer");
            return refuse(e);
        }
        if (e != DecodeError::None && e != DecodeError::BadMac) return refuse(e);
        if (seqValid && !newer(c.sequence, lastSeq)) return refuse("order");
        if (seqValid && uint32_t(c.sequence - lastSeq) > kMaxSequenceJump) return refuse("jump");
        seqValid = true;
        lastSeq = c.sequence;
        lastHeard = arrived;
        for (ArmCommand& a : c.arm) // the motors' limit, whatever the player asked
            if (const double f = a.servo_cf.force.norm(); f > kConsoleMaxForce) {
                a.servo_cf.force *= kConsoleMaxForce / f;
                ++clamped;
            }
        commanded = true;
        return true;
    }

    /// A command that verifies under a proposal from its own address opens that session.
    bool confirm(const uint8_t* data, size_t size, const Endpoint& from, CommandPacket& c) {
        for (auto p = proposals.rbegin(); p != proposals.rend(); ++p) {
            if (!(p->from == from)) continue;
            candidate.setKey(p->key);
            if (decode(data, size, c, candidate) != DecodeError::None) continue;
            session.setKey(p->key);
            player = from;
            havePlayer = true;
            seqValid = false;
            ++handshakes;
            proposals.clear();
            return true;
        }
        return false;
    }

    bool hello(const uint8_t* data, size_t size, const Endpoint& from, int64_t arrived, UdpSocket& sock) {
        HelloPacket h;
        if (const DecodeError e = decode(data, size, h, pairing); e != DecodeError::None) return refuse(e);
        if (std::find(nonces.begin(), nonces.end(), h.client) != nonces.end()) return refuse("replayed_hello");
        if (havePlayer && !(from == player) && arrived - lastHeard < kSessionIdleNs) return refuse("peer");
        nonces.push_back(h.client);
        WelcomePacket w;
        w.sequence = ++sendSeq;
        w.timestamp_ns = arrived;
        w.client = h.client;
        w.server = randomNonce();
        if (proposals.size() == kMaxPending) proposals.erase(proposals.begin());
        proposals.push_back({from, sessionKey(pairing, w.client, w.server)});
        uint8_t out[kMaxPacketSize];
        sock.sendTo(out, encode(w, out, sizeof out, pairing), from);
        return true;
    }
};

int writeTrajectory(const Options& o) {
    Source src(o);
    Trajectory out;
    const int n = static_cast<int>(std::floor(o.duration * o.rate));
    for (int k = 0; k <= n; ++k) {
        DeviceState s;
        src.sample(k / o.rate, s);
        for (int a = 0; a < src.arms(); ++a) {
            TrajectorySample ts;
            ts.t = k / o.rate;
            ts.pose = s.arms[a].measured_cp;
            ts.grip = s.arms[a].jaw_measured_js;
            ts.buttons = s.arms[a].buttons;
            ts.pedals = s.pedals;
            out.add(a, ts);
        }
    }
    writeFileAtomic(*o.writeTrajectory, out.format());
    std::printf("trajectory %s: %d samples per arm, %d arm(s), %.3f s\n", o.writeTrajectory->c_str(), n + 1, src.arms(),
                o.duration);
    return 0;
}

/// What the console sent and when (for the echo latency and the pause figures).
struct Stream {
    uint64_t sent = 0, sendErrors = 0;
    std::vector<std::pair<uint32_t, int64_t>> sentAt; ///< (sequence, time)
    double lastStateBeforeResume = 0;                 ///< s after t0
    double streamed = 0;                              ///< s from the session's start to the last state
};

/// The figures of a run: the force record, the summary JSON and the printed lines.
void writeFigures(const Options& o, const Link& link, const std::vector<Received>& received, const Stream& st,
                  int64_t t0) {
    // Figures: forces, pauses, echo latency.
    double maxForce = 0;
    uint64_t nonZero = 0, pausedCmds = 0, pausedNonZeroLate = 0, nonFinite = 0;
    std::vector<double> latency;
    size_t j = 0;
    for (const Received& r : received) {
        double f = 0;
        for (const auto& a : r.cmd.arm) {
            if (!a.servo_cf.force.allFinite()) ++nonFinite;
            f = std::max(f, a.servo_cf.force.norm());
        }
        maxForce = std::max(maxForce, f);
        nonZero += f > 0;
        if (r.paused) {
            ++pausedCmds;
            // Force still commanded 250 ms after the last state the player could have had: beyond
            // its device timeout (100 ms) and the slack of a loaded machine.
            if (f > 0 && r.t > st.lastStateBeforeResume + 0.25) ++pausedNonZeroLate;
        }
        while (j < st.sentAt.size() && newer(r.cmd.echoSequence, st.sentAt[j].first))
            ++j;
        if (!r.paused && j < st.sentAt.size() && st.sentAt[j].first == r.cmd.echoSequence)
            latency.push_back(1e-6 * double(int64_t(std::llround(r.t * 1e9)) + t0 - st.sentAt[j].second));
    }
    std::sort(latency.begin(), latency.end());
    auto pct = [&](double p) {
        return latency.empty() ? 0.0 : latency[std::min(latency.size() - 1, size_t(p * double(latency.size())))];
    };
    uint64_t rejectedAll = 0;
    for (const auto& [reason, count] : link.rejected)
        rejectedAll += count;
    if (o.record) {
        std::string csv = "t_s,seq,echo,flags,paused,f0x,f0y,f0z,f1x,f1y,f1z,grip0_n,grip1_n\n";
        char line[320];
        for (const Received& r : received) {
            const auto& a = r.cmd.arm;
            std::snprintf(line, sizeof line, "%.6f,%u,%u,%u,%d,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.4g,%.4g\n", r.t,
                          r.cmd.sequence, r.cmd.echoSequence, r.cmd.flags, int(r.paused), a[0].servo_cf.force.x(),
                          a[0].servo_cf.force.y(), a[0].servo_cf.force.z(), a[1].servo_cf.force.x(),
                          a[1].servo_cf.force.y(), a[1].servo_cf.force.z(), a[0].jaw_servo_jf, a[1].jaw_servo_jf);
            csv += line;
        }
        writeFileAtomic(*o.record, csv);
    }
    nlohmann::json sum = {{"duration_s", st.streamed},
                          {"states_sent", st.sent},
                          {"send_errors", st.sendErrors},
                          {"commands_received", received.size()},
                          {"commands_rejected", rejectedAll},
                          {"rejected", link.rejected},
                          {"handshakes", link.handshakes},
                          {"commands_clamped", link.clamped},
                          {"commands_nonzero", nonZero},
                          {"commands_non_finite", nonFinite},
                          {"max_force_n", maxForce},
                          {"paused_commands", pausedCmds},
                          {"paused_nonzero_after_timeout", pausedNonZeroLate},
                          {"last_state_before_resume_s", st.lastStateBeforeResume},
                          {"echo_latency_ms",
                           {{"count", latency.size()},
                            {"p50", pct(0.5)},
                            {"p99", pct(0.99)},
                            {"max", latency.empty() ? 0.0 : latency.back()}}}};
    if (o.summary) writeFileAtomic(*o.summary, sum.dump(2) + "\n");
    std::printf(
        "console-sim   %llu states sent, %zu commands received (%llu packets refused, %llu clamped to %.0f N), %llu "
        "non-zero, max force %.3f N, %llu sessions\n",
        (unsigned long long)st.sent, received.size(), (unsigned long long)rejectedAll, (unsigned long long)link.clamped,
        kConsoleMaxForce, (unsigned long long)nonZero, maxForce, (unsigned long long)link.handshakes);
    std::printf("latency       state -> command echo p50 %.3f ms, p99 %.3f ms\n", pct(0.5), pct(0.99));
    if (pausedCmds)
        std::printf("pause         %llu commands during the pause, %llu non-zero after the device timeout\n",
                    (unsigned long long)pausedCmds, (unsigned long long)pausedNonZeroLate);
}

int makePairingKey(const std::string& path) {
    requireWritableFile(path, "the pairing key");
    writeFileAtomic(path, formatPairingKey(randomKey()), 0600);
    std::printf("pairing key   %s (64 hex digits, readable by its owner only; give it to the player with "
                "--pairing-key)\n",
                std::filesystem::absolute(path).c_str());
    return 0;
}

int run(const Options& o) {
    if (!o.pairingKey)
        throw std::invalid_argument("--pairing-key FILE is needed: the key the player has (--make-pairing-key FILE "
                                    "makes one)");
    std::vector<std::filesystem::path> inputs;
    if (o.trajectory) inputs.emplace_back(*o.trajectory);
    for (const auto& [file, what] : {std::pair{o.record, "the force record"}, std::pair{o.summary, "the summary"}})
        if (file) { // before the session, whose record would be lost at its end
            requireWritableFile(*file, what);
            requireNotAnInput(*file, what, inputs);
        }
    Source src(o);
    const double duration = o.duration > 0 ? o.duration : src.duration();
    if (!(duration > 0))
        throw std::invalid_argument("--duration is needed with a script (or a trajectory shorter than 1 ms)");
    UdpSocket sock(parseEndpoint(o.listen, "--listen", true), 1 << 20);
    const Endpoint local = sock.local();
    if (o.portFile) writeFileAtomic(*o.portFile, std::to_string(ntohs(local.addr.sin_port)) + "\n");
    std::fprintf(stderr, "viscera-console-sim: listening on %s\n", local.text().c_str());

    std::vector<Received> received;
    received.reserve(static_cast<size_t>(duration * o.rate * 1.2) + 1024);
    Link link(loadPairingKey(*o.pairingKey));
    uint8_t buf[kMaxPacketSize];
    const int64_t waitEnd = monotonicNs() + int64_t(o.waitPlayer * 1e9);
    int64_t t0 = 0;
    auto drain = [&]() {
        while (true) {
            Endpoint from;
            int64_t queued = 0;
            const long n = sock.receive(buf, sizeof buf, &from, &queued);
            if (n < 0) break;
            const int64_t arrived = monotonicNs() - queued;
            CommandPacket c;
            const bool hadPlayer = link.havePlayer;
            if (!link.take(buf, n > long(sizeof buf) ? sizeof buf + 1 : size_t(n), from, arrived, sock, c)) continue;
            if (!hadPlayer && link.havePlayer) {
                t0 = arrived;
                std::fprintf(stderr, "viscera-console-sim: player at %s\n", link.player.text().c_str());
            }
            if (!link.commanded) continue; // the handshake
            // Time the command arrived, not when this loop got to it (the figures judge the
            // player's forces by when it sent them, whatever the load on this process).
            const double t = 1e-9 * double(arrived - t0);
            received.push_back({t, o.pauseAt >= 0 && t >= o.pauseAt && t < o.pauseAt + o.pauseFor, c});
        }
    };
    while (!link.havePlayer) {
        if (monotonicNs() > waitEnd) {
            std::fprintf(stderr, "viscera-console-sim: no player contacted %s within %.1f s\n", local.text().c_str(),
                         o.waitPlayer);
            return 3;
        }
        sock.wait(50);
        drain();
    }
    const int64_t period = int64_t(std::llround(1e9 / o.rate));
    uint32_t seq = 0;
    Stream st;
    st.sentAt.reserve(static_cast<size_t>(duration * o.rate) + 16);
    int64_t next = t0;
    DeviceState s;
    constexpr int64_t kPlayerSilentNs = 1'000'000'000;
    while (true) {
        const int64_t now = monotonicNs();
        const double t = 1e-9 * double(now - t0);
        if (t > duration) break;
        drain();
        if (o.untilPlayerStops && now - link.lastHeard > kPlayerSilentNs) break;
        st.streamed = t;
        const bool paused = o.pauseAt >= 0 && t >= o.pauseAt && t < o.pauseAt + o.pauseFor;
        if (!paused) {
            src.sample(t, s);
            StatePacket p;
            p.sequence = ++seq;
            p.timestamp_ns = now;
            p.pedals = s.pedals;
            p.arms = static_cast<uint8_t>(src.arms());
            for (int a = 0; a < kMaxArms; ++a)
                p.arm[a] = s.arms[a];
            const size_t n = encode(p, buf, sizeof buf, link.session);
            if (sock.sendTo(buf, n, link.player)) {
                ++st.sent, st.sentAt.emplace_back(p.sequence, now);
                // When the last state before the silence really left (this process may have
                // been descheduled between reading the clock and sending).
                const double left = 1e-9 * double(monotonicNs() - t0);
                if (o.pauseAt >= 0 && left < o.pauseAt + o.pauseFor)
                    st.lastStateBeforeResume = std::max(st.lastStateBeforeResume, left);
            } else
                ++st.sendErrors;
        }
        next += period;
        sleepUntil(next);
    }
    const int64_t tail = monotonicNs() + 200'000'000;
    while (monotonicNs() < tail) {
        sock.wait(20);
        drain();
    }

    writeFigures(o, link, received, st, t0);
    return 0;
}

void usage(std::FILE* out) {
    std::fputs("usage: viscera-console-sim --listen HOST:PORT --pairing-key FILE (--trajectory FILE | --script NAME)\n"
               "           [--duration S] [--rate HZ] [--loop] [--record forces.csv] [--summary summary.json]\n"
               "           [--port-file FILE] [--pause-at S --pause-for S] [--wait-player S] [--until-player-stops]\n"
               "       viscera-console-sim --write-trajectory OUT.csv --script NAME --duration S [--rate HZ]\n"
               "       viscera-console-sim --make-pairing-key FILE\n"
               "       viscera-console-sim --version\n",
               out);
}

} // namespace

int main(int argc, char** argv) {
    sim::CliProgram program;
    program.name = "viscera-console-sim";
    program.version = VISCERA_VERSION;
    program.usage = usage;
    program.fallback = [](const sim::CliArgs& args) {
        const Options o = parse(args);
        if (o.makePairingKey) return makePairingKey(*o.makePairingKey);
        return o.writeTrajectory ? writeTrajectory(o) : run(o);
    };
    return sim::runCli(program, argc, argv);
}
