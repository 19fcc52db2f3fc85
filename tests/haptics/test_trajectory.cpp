// Trajectory files: parsing, every rejection with its line and field, formatting round trip,
// interpolation on the deterministic clock.
#include "haptics/trajectory.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::haptics;
using ::testing::HasSubstr;

namespace {

const std::string kHead = "# viscera-trajectory 1\nt,arm,x,y,z,qw,qx,qy,qz,grip,buttons,pedals\n";

std::string rejection(const std::string& body) {
    try {
        Trajectory::parse(kHead + body, "traj.csv");
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

} // namespace

TEST(Trajectory, ParsesAndInterpolates) {
    const Trajectory t = Trajectory::parse(kHead + "# a comment\n"
                                                   "0.0,0,0,0,0,1,0,0,0,0.0,0,4\n"
                                                   "1.0,0,0.1,0,0,1,0,0,0,0.5,1,5\n"
                                                   "0.5,1,0,0,0.2,1,0,0,0,0,0,0\n",
                                           "traj.csv");
    EXPECT_EQ(t.arms(), 2);
    EXPECT_DOUBLE_EQ(t.duration(), 1.0);
    DeviceState s;
    t.sampleInto(0.25, false, s);
    EXPECT_NEAR(s.arms[0].measured_cp.position.x(), 0.025, 1e-12);
    EXPECT_NEAR(s.arms[0].measured_cv.linear.x(), 0.1, 1e-12);
    EXPECT_NEAR(s.arms[0].jaw_measured_js, 0.125, 1e-12);
    EXPECT_EQ(s.pedals, 4u); // previous sample's pedals
    EXPECT_NEAR(s.arms[1].measured_cp.position.z(), 0.2, 1e-12);
    t.sampleInto(5.0, false, s); // after the end the last sample holds
    EXPECT_NEAR(s.arms[0].measured_cp.position.x(), 0.1, 1e-12);
    EXPECT_EQ(s.arms[0].buttons, 1u);
    EXPECT_EQ(s.arms[0].measured_cv.linear.norm(), 0.0);
    t.sampleInto(1.25, true, s); // looping wraps to 0.25
    EXPECT_NEAR(s.arms[0].measured_cp.position.x(), 0.025, 1e-12);
}

TEST(Trajectory, FormatRoundTrips) {
    Trajectory t;
    for (int k = 0; k < 10; ++k) {
        TrajectorySample s;
        s.t = 0.01 * k;
        s.pose.position = Vec3(0.001 * k, -0.002 * k, 0.05);
        s.pose.orientation = Quat(Eigen::AngleAxisd(0.1 * k, Vec3::UnitX()));
        s.grip = 0.2;
        s.pedals = kPedalDeadman;
        t.add(0, s);
    }
    const Trajectory u = Trajectory::parse(t.format(), "round");
    ASSERT_EQ(u.samples(0).size(), 10u);
    EXPECT_TRUE(u.samples(0)[7].pose.position.isApprox(t.samples(0)[7].pose.position, 1e-8));
    EXPECT_TRUE(u.samples(0)[7].pose.orientation.isApprox(t.samples(0)[7].pose.orientation, 1e-8));
    EXPECT_THROW(t.add(0, TrajectorySample{}), std::invalid_argument); // t does not increase
}

TEST(Trajectory, RejectsEachMalformedLineNamingLineAndField) {
    struct Bad {
        std::string body;
        const char* rule;
    };
    const std::vector<Bad> bad = {
        {"0,0,0,0,0,1,0,0,0,0,0\n", "line 3: has 11 fields, expected 12"},
        {"0,0,0,0,0,1,0,0,0,0,0,4,9\n", "line 3: has more than 12 fields"},
        {"0,0,abc,0,0,1,0,0,0,0,0,4\n", "line 3: field 'x': not a number"},
        {"0,0,0,0,nan,1,0,0,0,0,0,4\n", "line 3: field 'z': must be finite"},
        {"0,0,0,0,1e400,1,0,0,0,0,0,4\n", "field 'z': must be finite"},
        {"-1,0,0,0,0,1,0,0,0,0,0,4\n", "field 't': must not be negative"},
        {"0,2,0,0,0,1,0,0,0,0,0,4\n", "field 'arm': must be 0 or 1"},
        {"0,0.5,0,0,0,1,0,0,0,0,0,4\n", "field 'arm': must be 0 or 1"},
        {"0,0,11,0,0,1,0,0,0,0,0,4\n", "field 'x': must be within ±10 m"},
        {"0,0,0,0,0,0,0,0,0,0,0,4\n", "the quaternion norm"},
        {"0,0,0,0,0,1,0,0,0,4,0,4\n", "field 'grip': must be in [0, pi]"},
        {"0,0,0,0,0,1,0,0,0,0,-1,4\n", "field 'buttons'"},
        {"0,0,0,0,0,1,0,0,0,0,0,32\n", "field 'pedals': must be an integer in [0, 31]"},
        {"1,0,0,0,0,1,0,0,0,0,0,4\n1,0,0,0,0,1,0,0,0,0,0,4\n", "line 4: field 't': must increase"},
        {"0,0,,0,0,1,0,0,0,0,0,4\n", "field 'x': not a number"},
        {"", "contains no sample"},
    };
    for (const Bad& b : bad) {
        const std::string msg = rejection(b.body);
        EXPECT_THAT(msg, HasSubstr("traj.csv")) << b.body;
        EXPECT_THAT(msg, HasSubstr(b.rule)) << b.body;
        EXPECT_EQ(msg.find('\n'), std::string::npos);
    }
    auto headerError = [](const std::string& text) {
        try {
            Trajectory::parse(text, "h.csv");
        } catch (const viscera::InputError& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    EXPECT_THAT(headerError(""), HasSubstr("h.csv: empty file"));
    EXPECT_THAT(headerError("# viscera-trajectory 2\n"), HasSubstr("line 1: the first line must be"));
    EXPECT_THAT(headerError("# viscera-trajectory 1\nt,x\n"), HasSubstr("line 2: the column header must be"));
    EXPECT_THROW(Trajectory::load("/nonexistent/traj.csv"), viscera::InputError);
}
