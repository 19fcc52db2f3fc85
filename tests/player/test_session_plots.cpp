// Session timeline and plots [issue 18 item 4]: the timeline the session records (tool tips,
// forces, events; bounded on long sessions), the report's timeline read back by the one plot
// reader, malformed reports refused naming the field, the charts drawn from the data and the
// self-contained page.
#include "haptics/device_spec.hpp"
#include "player/haptic_case.hpp"
#include "plots/session_plots.hpp"
#include "runtime/report.hpp"
#include "runtime/session.hpp"
#include "runtime/timeline.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"

#include <QByteArray>
#include <QColor>
#include <QImage>

#include <gtest/gtest.h>

#include <cmath>

using namespace viscera;
using nlohmann::json;

namespace {

/// The test cases are made here unsigned; the signature rules have tests of their own.
vcase::TrustPolicy unsignedAllowed() {
    vcase::TrustPolicy p;
    p.allowUnsigned = true;
    return p;
}

/// The haptic sample case (a block with one probe above it) run with scripted:press.
struct PressedSession {
    test::Scratch scratch{"viscera-plots"};
    player::SessionResult result;
    json report;
    PressedSession() {
        const std::string casePath = scratch / "haptic.vcase";
        test::writeHapticCase(casePath);
        player::LoadedCase loaded = player::loadCase(casePath, unsignedAllowed());
        auto dev = haptics::openDevice(haptics::parseDeviceSpec("scripted:press"));
        player::RunOptions o;
        o.frames = 120;
        o.device = dev.get();
        o.deviceSpec = "scripted:press";
        result = player::runSession(loaded, o);
        report = player::reportJson(result);
    }
};

const PressedSession& pressed() {
    static const PressedSession s;
    return s;
}

/// Pixels of `png` within 12 of `c` in every channel.
int pixelsOf(const std::filesystem::path& png, const QColor& c) {
    QImage img(QString::fromStdString(png.string()));
    int n = 0;
    for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
            const QColor p = img.pixelColor(x, y);
            n += std::abs(p.red() - c.red()) <= 12 && std::abs(p.green() - c.green()) <= 12 &&
                 std::abs(p.blue() - c.blue()) <= 12;
        }
    return n;
}

const QColor kFirstTool(31, 119, 180); // the first tool's colour in every chart

std::string refusal(json doc) {
    try {
        player::readPlotInput(doc, "r.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

} // namespace

TEST(SessionTimeline, RecordsTheProbeEveryFrameWithItsForce) {
    const player::SessionResult& r = pressed().result;
    const player::SessionTimeline& tl = r.timeline;
    ASSERT_EQ(tl.tools.size(), 1u);
    EXPECT_EQ(tl.tools[0].kind, "probe");
    EXPECT_EQ(tl.stride, 1);
    ASSERT_EQ(tl.t_s.size(), r.frames.size());
    ASSERT_EQ(tl.tools[0].tip.size(), tl.t_s.size());
    EXPECT_NEAR(tl.t_s.back(), r.simTime, 1e-9);
    double fmax = 0, zmin = 1e9, zmax = -1e9;
    for (size_t i = 0; i < tl.t_s.size(); ++i) {
        fmax = std::max(fmax, tl.tools[0].force_n[i]);
        zmin = std::min(zmin, tl.tools[0].tip[i].z());
        zmax = std::max(zmax, tl.tools[0].tip[i].z());
    }
    EXPECT_GT(fmax, 0.0);                             // the press reaches the tissue
    EXPECT_EQ(fmax, r.assessment.tools[0].forceMaxN); // the same force the metrics keep
    EXPECT_GT(zmax - zmin, 1e-3);                     // and the probe went down
}

TEST(SessionTimeline, StaysBoundedOnALongSessionWithAUniformStride) {
    test::Scratch scratch("viscera-timeline");
    test::writeHapticCase(scratch / "haptic.vcase");
    player::LoadedCase loaded = player::loadCase(scratch / "haptic.vcase", unsignedAllowed());
    sim::World& world = *loaded.world;
    player::TimelineRecorder rec(world, 16);
    for (int f = 0; f < 100; ++f) {
        world.setToolPosition(0, world.toolDesc(0).start - sim::Vec3(0, 0, 1e-4 * f));
        world.step();
        rec.record(world);
    }
    const player::SessionTimeline& tl = rec.timeline();
    EXPECT_LE(tl.t_s.size(), 16u);
    EXPECT_GE(tl.t_s.size(), 8u);
    EXPECT_EQ(tl.stride, 8); // 100 frames: 16 → halved three times
    for (size_t i = 1; i < tl.t_s.size(); ++i)
        EXPECT_NEAR(tl.t_s[i] - tl.t_s[i - 1], tl.stride * world.dt(), 1e-9);
    ASSERT_EQ(tl.tools[0].tip.size(), tl.t_s.size());
    EXPECT_NEAR(tl.tools[0].tip.back().z(), world.toolDesc(0).start.z() - 1e-4 * 96, 1e-9); // frame 96 sampled
}

TEST(SessionPlots, TheReportsTimelineReadsBack) {
    const PressedSession& s = pressed();
    ASSERT_TRUE(s.report.contains("timeline"));
    const player::PlotInput in = player::readPlotInput(s.report, "r.json");
    EXPECT_TRUE(in.hasTimeline);
    ASSERT_EQ(in.tools.size(), 1u);
    EXPECT_EQ(in.tools[0].name, s.result.timeline.tools[0].name);
    ASSERT_EQ(in.t_s.size(), s.result.timeline.t_s.size());
    for (size_t i = 0; i < in.t_s.size(); i += 17) {
        EXPECT_NEAR(in.tools[0].tip[i][2], s.result.timeline.tools[0].tip[i].z(), 1e-6); // rounded to 1 µm
        EXPECT_NEAR(in.tools[0].forceN[i], s.result.timeline.tools[0].force_n[i], 1e-4);
    }
    EXPECT_EQ(in.frames.size(), s.result.frames.size());
    EXPECT_NEAR(in.tools[0].pathM, s.result.assessment.tools[0].pathM, 1e-15);
    EXPECT_EQ(in.device, "scripted:press");
}

TEST(SessionPlots, ChartsDrawTheDataAndThePageEmbedsThem) {
    const PressedSession& s = pressed();
    test::Scratch out("viscera-plots-out");
    const player::PlotFiles files = player::writeSessionPlots(player::readPlotInput(s.report, "r.json"), out.dir / "p");
    ASSERT_EQ(files.images.size(), 5u); // no sampled accuracy in this case: no accuracy chart
    for (const auto& p : files.images) {
        QImage img(QString::fromStdString(p.string()));
        ASSERT_FALSE(img.isNull()) << p;
        EXPECT_GE(img.width(), 1000) << p;
    }
    // The force curve is drawn in the first tool's colour; without the tool it is not.
    EXPECT_GT(pixelsOf(out.dir / "p/forces.png", kFirstTool), 200);
    json noTools = s.report;
    noTools["timeline"]["tools"] = json::array();
    const auto bare = player::writeSessionPlots(player::readPlotInput(noTools, "r.json"), out.dir / "q");
    EXPECT_EQ(pixelsOf(out.dir / "q/forces.png", kFirstTool), 0);

    const std::string page = readFile(files.page);
    size_t embedded = 0;
    for (size_t at = page.find("data:image/png;base64,"); at != std::string::npos;
         at = page.find("data:image/png;base64,", at + 1))
        ++embedded;
    EXPECT_EQ(embedded, files.images.size());
    EXPECT_EQ(page.find("src=\"http"), std::string::npos);
    EXPECT_EQ(page.find("<link"), std::string::npos);
    // The first embedded image is the step-time chart's bytes.
    const size_t b = page.find("base64,") + 7, e = page.find('"', b);
    const QByteArray decoded = QByteArray::fromBase64(QByteArray::fromStdString(page.substr(b, e - b)));
    EXPECT_EQ(decoded.toStdString(), readFile(out.dir / "p/step_time.png"));
    EXPECT_NE(page.find("scripted:press"), std::string::npos);
}

TEST(SessionPlots, AFigureTheSessionCouldNotComputeIsAGapNotANumber) {
    json doc = pressed().report;
    doc["frames"][3]["energy_j"] = nullptr; // how nlohmann writes NaN
    doc["metrics"]["step_ms_mean"] = nullptr;
    doc["metrics"]["sim_time_s"] = nullptr;
    doc["timeline"]["tools"][0]["tip_m"][4] = json::array({nullptr, nullptr, nullptr});
    const player::PlotInput in = player::readPlotInput(doc, "r.json");
    EXPECT_TRUE(std::isnan(in.frames[3].energyJ));
    EXPECT_TRUE(std::isnan(in.stepMsMean));
    EXPECT_TRUE(std::isnan(in.tools[0].tip[4][0]));
    test::Scratch out("viscera-plots-nan");
    const auto files = player::writeSessionPlots(in, out.dir);
    std::string page = readFile(files.page);
    for (size_t a = page.find("data:image/png;base64,"); a != std::string::npos;
         a = page.find("data:image/png;base64,", a)) // the text only, not the images' base64
        page.erase(a, page.find('"', a) - a);
    EXPECT_NE(page.find("mean — ms"), std::string::npos) << "the missing figure is shown as missing";
    EXPECT_EQ(page.find("nan"), std::string::npos);
    EXPECT_EQ(page.find("inf"), std::string::npos);
}

TEST(SessionPlots, ANonFiniteValueInTheSessionIsWrittenAsNullAndReadAsAGap) {
    player::SessionResult r = pressed().result;
    r.timeline.tools[0].tip[2] = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    r.timeline.tools[0].force_n[2] = std::numeric_limits<double>::infinity();
    const json doc = json::parse(player::reportJson(r).dump()); // as a saved report
    EXPECT_TRUE(doc["timeline"]["tools"][0]["tip_m"][2][0].is_null());
    EXPECT_TRUE(doc["timeline"]["tools"][0]["force_n"][2].is_null());
    const player::PlotInput in = player::readPlotInput(doc, "r.json");
    EXPECT_TRUE(std::isnan(in.tools[0].tip[2][1]));
    EXPECT_TRUE(std::isnan(in.tools[0].forceN[2]));
}

TEST(SessionPlots, MalformedReportsAreRefusedNamingTheField) {
    const json ok = pressed().report;
    json d = ok;
    d.erase("schemaVersion");
    EXPECT_EQ(refusal(d), "r.json: schemaVersion: is missing");
    d = ok;
    d["schemaVersion"] = 9;
    EXPECT_EQ(refusal(d), "r.json: schemaVersion: 9 is newer than this player reads (5)");
    d = ok;
    d["frames"][1]["step_ms"] = "fast";
    EXPECT_EQ(refusal(d), "r.json: frames[1].step_ms: must be a number");
    d = ok;
    d["frames"][1]["step_ms"] = -1;
    EXPECT_EQ(refusal(d), "r.json: frames[1].step_ms: must not be negative");
    d = ok;
    d["metrics"]["frame_dt_s"] = 0;
    EXPECT_EQ(refusal(d), "r.json: metrics.frame_dt_s: must be positive");
    d = ok;
    d["timeline"]["tools"][0]["force_n"].erase(0);
    EXPECT_EQ(refusal(d), "r.json: timeline.tools[0].force_n: has " + std::to_string(ok["timeline"]["t_s"].size() - 1) +
                              " samples, timeline.t_s has " + std::to_string(ok["timeline"]["t_s"].size()));
    d = ok;
    d["timeline"]["tools"][0]["tip_m"][2] = json::array({1, 2});
    EXPECT_EQ(refusal(d), "r.json: timeline.tools[0].tip_m[2]: must be [x, y, z]");
    d = ok;
    d["timeline"]["t_s"][5] = 0.0;
    EXPECT_EQ(refusal(d), "r.json: timeline.t_s[5]: times must be finite and must not decrease");
    d = ok;
    d["timeline"]["events"] = json::array({{{"t_s", 0.1}, {"kind", "cut"}, {"tool", "hook"}, {"count", 0}}});
    EXPECT_EQ(refusal(d), "r.json: timeline.events[0].count: must be at least 1");
    EXPECT_EQ(refusal(json::array()), "r.json: (document): a session report must be a JSON object");
    d = ok;
    d["schemaVersion"] = 4294967298ull; // would wrap to 2 as an int
    EXPECT_EQ(refusal(d), "r.json: schemaVersion: is out of range");
    d = ok;
    d["timeline"]["events"] =
        json::array({{{"t_s", 0.1}, {"kind", "cut"}, {"tool", "hook"}, {"count", -4294967295ll}}});
    EXPECT_EQ(refusal(d), "r.json: timeline.events[0].count: is out of range");

    test::Scratch dir("viscera-plots-bad");
    writeFileAtomic(dir / "broken.json", "{\"schemaVersion\": 2,");
    try {
        player::readPlotInputFile(dir / "broken.json");
        FAIL() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(dir / "broken.json" + ": not a JSON session report (parse error at", 0),
                  0u)
            << e.what();
    }
    // A number past a double's range (found by fuzz_session_report): refused as input, naming it.
    writeFileAtomic(dir / "big.json", "{\"schemaVersion\": 1e400}");
    try {
        player::readPlotInputFile(dir / "big.json");
        FAIL() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  dir / "big.json" + ": not a JSON session report (number overflow parsing '1e400')");
    }
}
