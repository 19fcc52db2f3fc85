// The session record reader (one rule per field, one-line messages) and the proficiency rule.
#include "player/results/report_generator.hpp"
#include "results/learning_curve.hpp"
#include "results/session_record.hpp"

#include "sim/util/error.hpp"

#include <gtest/gtest.h>

#include <functional>

namespace {

using nlohmann::json;
using viscera::player::readSessionRecord;

std::string refusal(const std::function<void(json&)>& edit) {
    json doc = viscera::test::improvingReport("t01", 6);
    edit(doc);
    try {
        readSessionRecord(doc, "r.json");
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

TEST(SessionRecord, ReadsTheRecordAndTheAssessment) {
    const auto s = readSessionRecord(viscera::test::improvingReport("t01", 6), "r.json");
    EXPECT_EQ(s.trainee, "t01");
    EXPECT_EQ(s.caseId, "rectum");
    EXPECT_EQ(s.caseVersion, "1.2.0");
    EXPECT_EQ(s.startedUtc, "2026-11-06T09:16:00Z");
    EXPECT_TRUE(s.passed);
    EXPECT_EQ(*s.completionTime_s, 13.0);
    ASSERT_EQ(s.metrics.size(), 4u);
    EXPECT_FALSE(s.metrics[2].lowerIsBetter);
    EXPECT_DOUBLE_EQ(s.metrics[2].expert->bound, 0.84);
    EXPECT_TRUE(*s.metrics[2].withinExpert);
    EXPECT_FALSE(s.metrics[1].limit.has_value());
    EXPECT_FALSE(s.metrics[3].expert.has_value());
}

TEST(SessionRecord, RefusesMalformedFieldsNamingThem) {
    EXPECT_EQ(refusal([](json& d) { d.erase("record"); }),
              "r.json: record: is missing (the report has no trainee record; reports before schema 5 have none)");
    EXPECT_EQ(refusal([](json& d) { d.erase("assessment"); }),
              "r.json: assessment: is missing (the session was not assessed)");
    EXPECT_EQ(refusal([](json& d) { d["schemaVersion"] = 6; }),
              "r.json: schemaVersion: 6 is newer than this program reads (5)");
    EXPECT_EQ(refusal([](json& d) { d["record"]["trainee"] = ""; }), "r.json: record.trainee: must not be empty");
    EXPECT_EQ(refusal([](json& d) { d["record"]["started_utc"] = "yesterday"; }),
              "r.json: record.started_utc: must be a UTC time like 2026-12-05T19:50:00Z");
    EXPECT_EQ(refusal([](json& d) { d["record"]["package_sha256"] = "ABC"; }),
              "r.json: record.package_sha256: must be 64 lowercase hex digits");
    EXPECT_EQ(refusal([](json& d) { d["assessment"]["passed"] = "yes"; }),
              "r.json: assessment.passed: must be true or false");
    EXPECT_EQ(refusal([](json& d) { d["assessment"]["metrics"][0].erase("unit"); }),
              "r.json: assessment.metrics[0].unit: is missing");
    EXPECT_EQ(refusal([](json& d) { d["assessment"]["metrics"][2]["expert"]["sd"] = -1; }),
              "r.json: assessment.metrics[2].expert.sd: must not be negative");
    EXPECT_EQ(refusal([](json& d) { d["assessment"]["metrics"][3]["within_expert"] = true; }),
              "r.json: assessment.metrics[3].within_expert: must be null when the metric has no expert level");
    EXPECT_EQ(refusal([](json& d) { d["assessment"]["metrics"][1]["value"] = "1"; }),
              "r.json: assessment.metrics[1].value: must be a number");
    EXPECT_EQ(refusal([](json& d) { d["assessment"]["metrics"][1]["name"] = "completion_time_s"; }),
              "r.json: assessment.metrics[1].name: 'completion_time_s' is given twice");
}

TEST(LearningCurve, ProficientAtTheSecondOfTwoConsecutiveExpertAttempts) {
    std::vector<viscera::player::SessionRecord> sessions;
    for (int a = 10; a >= 1; --a) // stored newest first: the curve orders by start time
        sessions.push_back(readSessionRecord(viscera::test::improvingReport("t01", a), "r.json"));
    for (int a = 1; a <= 6; ++a)
        sessions.push_back(readSessionRecord(viscera::test::strugglingReport("t02", a), "r.json"));
    const auto curves = viscera::player::learningCurves(sessions);
    ASSERT_EQ(curves.size(), 2u);
    EXPECT_EQ(curves[0].trainee, "t01");
    EXPECT_EQ(curves[0].attempts[0].session->startedUtc, "2026-11-01T09:11:00Z");
    ASSERT_TRUE(curves[0].proficientAt.has_value());
    EXPECT_EQ(*curves[0].proficientAt, 7);
    EXPECT_EQ(curves[0].verdict(), "proficient at attempt 7");
    EXPECT_FALSE(curves[1].proficientAt.has_value());
    EXPECT_EQ(curves[1].verdict(), "not yet proficient (attempt 6 at expert level; one more in a row needed)");
}

} // namespace
