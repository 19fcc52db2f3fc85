// Recorded instrument tracks: parse/format round trip, interpolation, and one-line rejections.
#include "sim/scene/instrument_track.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera;
using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {
const char* kGood = "# viscera instrument track 1\n"
                    "# t x y z dx dy dz jaw act\n"
                    "0.0  0.0 0.0 0.03   0 0 -1   1.0 0\n"
                    "\n"
                    "1.0  0.02 0.0 0.01  0 0 -2   0.0 1\n"
                    "2.0  0.02 0.02 0.01 1 0 0    0.5 0\n";

std::string errorOf(const std::string& text) {
    try {
        InstrumentTrack::parse(text, "tools/hook.track");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
} // namespace

TEST(InstrumentTrack, ParsesInterpolatesAndRoundTrips) {
    const InstrumentTrack t = InstrumentTrack::parse(kGood, "tools/hook.track");
    ASSERT_EQ(t.keys().size(), 3u);
    EXPECT_DOUBLE_EQ(t.duration(), 2.0);
    EXPECT_NEAR((t.keys()[1].direction - Vec3(0, 0, -1)).norm(), 0, 1e-15) << "directions are normalised";
    const InstrumentKey mid = t.sample(0.25);
    EXPECT_NEAR((mid.position - Vec3(0.005, 0, 0.025)).norm(), 0, 1e-15);
    EXPECT_NEAR(mid.jaw, 0.75, 1e-15);
    EXPECT_FALSE(mid.act) << "act holds the earlier key";
    EXPECT_TRUE(t.sample(1.5).act);
    EXPECT_NEAR(t.sample(1.5).direction.norm(), 1.0, 1e-12);
    EXPECT_NEAR((t.sample(-1).position - t.keys()[0].position).norm(), 0, 0) << "held before the first key";
    EXPECT_NEAR((t.sample(9).position - t.keys()[2].position).norm(), 0, 0) << "held after the last key";
    const InstrumentTrack back = InstrumentTrack::parse(t.format(), "again");
    ASSERT_EQ(back.keys().size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_NEAR((back.keys()[i].position - t.keys()[i].position).norm(), 0, 1e-9);
        EXPECT_EQ(back.keys()[i].act, t.keys()[i].act);
    }
}

TEST(InstrumentTrack, RejectsMalformedFilesWithFileLineAndRule) {
    EXPECT_THAT(errorOf(""), HasSubstr("tools/hook.track:1: header"));
    EXPECT_THAT(errorOf("0 0 0 0 0 0 1 1 0\n"), HasSubstr("tools/hook.track:1: header"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n# nothing\n"),
                HasSubstr("keys: a track needs at least one key"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n0 0 0 0 0 0 1 1\n"), HasSubstr(":2: key: expected 9 numbers"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n0 0 0 0 0 0 1 1 0 7\n"),
                HasSubstr(":2: key: expected 9 numbers"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n0 0 zero 0 0 0 1 1 0\n"),
                HasSubstr(":2: key: 'zero' is not a number"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n0 nan 0 0 0 0 1 1 0\n"),
                HasSubstr(":2: position: must be finite"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n0 0 0 0 0 0 0 1 0\n"), HasSubstr(":2: direction"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n0 0 0 0 0 0 1 1.5 0\n"),
                HasSubstr(":2: jaw: must be in [0, 1]"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n0 0 0 0 0 0 1 1 2\n"), HasSubstr(":2: act: must be 0 or 1"));
    EXPECT_THAT(errorOf("# viscera instrument track 1\n1 0 0 0 0 0 1 1 0\n1 0 0 0 0 0 1 1 0\n"),
                HasSubstr(":3: t: times must strictly increase"));
    EXPECT_THROW(InstrumentTrack(std::vector<InstrumentKey>{}), std::invalid_argument);
}
