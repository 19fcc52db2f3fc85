#include "results/session_record.hpp"

#include "runtime/assessment_json.hpp"
#include "runtime/report_reader.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <openssl/evp.h>

#include <cmath>
#include <regex>
#include <set>

namespace viscera::player {

namespace {

using nlohmann::json;

struct Reader : ReportReader {
    std::string nonEmpty(const json& obj, const std::string& parent, const char* key) const {
        const std::string field = parent + "." + key;
        std::string s = string(member(obj, parent, key), field);
        if (s.empty()) fail(field, "must not be empty");
        if (s.size() > 200) fail(field, "must be at most 200 characters");
        for (unsigned char c : s)
            if (c < 0x20) fail(field, "must not contain control characters");
        return s;
    }
};

/// The one reader of a report's metric entry (runtime/assessment_json.hpp), as the database keeps it.
MetricRecord readMetric(const Reader& rd, const json& m, const std::string& f) {
    const MetricResult r = readMetricJson(rd, m, f);
    MetricRecord out;
    out.name = r.name;
    out.unit = r.unit;
    out.value = r.value;
    out.lowerIsBetter = r.lowerIsBetter;
    out.limit = r.limit;
    out.passed = r.passed;
    if (r.expert) out.expert = ExpertLevel{r.expert->mean, r.expert->sd, r.bound};
    out.withinExpert = r.withinExpert;
    return out;
}

} // namespace

SessionRecord readSessionRecord(const json& doc, const std::string& origin) {
    const Reader rd{{origin}};
    if (!doc.is_object()) rd.fail("(document)", "a session report must be a JSON object");
    const json& sv = rd.member(doc, "", "schemaVersion");
    if (!sv.is_number_integer()) rd.fail("schemaVersion", "must be an integer");
    const int64_t schema = sv.get<int64_t>();
    if (schema > kResultsNewestSchema)
        rd.fail("schemaVersion", std::to_string(schema) + " is newer than this program reads (" +
                                     std::to_string(kResultsNewestSchema) + ")");
    if (!doc.contains("record"))
        rd.fail("record", "is missing (the report has no trainee record; reports before schema " +
                              std::to_string(kResultsOldestSchema) + " have none)");
    if (!doc.contains("assessment")) rd.fail("assessment", "is missing (the session was not assessed)");
    if (schema < kResultsOldestSchema)
        rd.fail("schemaVersion", "must be at least " + std::to_string(kResultsOldestSchema));

    SessionRecord s;
    s.origin = origin;
    const json& r = doc["record"];
    if (!r.is_object()) rd.fail("record", "must be an object");
    s.trainee = rd.nonEmpty(r, "record", "trainee");
    s.startedUtc = rd.nonEmpty(r, "record", "started_utc");
    // Whole seconds, as the player writes it: attempts are ordered by this text.
    static const std::regex utc(R"(\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}Z)");
    if (!std::regex_match(s.startedUtc, utc))
        rd.fail("record.started_utc", "must be a UTC time like 2026-12-05T19:50:00Z");
    s.playerVersion = rd.nonEmpty(r, "record", "player_version");
    s.caseId = rd.nonEmpty(r, "record", "case_id");
    s.caseVersion = rd.nonEmpty(r, "record", "case_version");
    s.packageSha256 = rd.nonEmpty(r, "record", "package_sha256");
    static const std::regex hex("[0-9a-f]{64}");
    if (!std::regex_match(s.packageSha256, hex)) rd.fail("record.package_sha256", "must be 64 lowercase hex digits");

    const json& a = doc["assessment"];
    if (!a.is_object()) rd.fail("assessment", "must be an object");
    if (const auto j = a.find("judged"); j != a.end() && j->is_boolean() && !j->get<bool>())
        rd.fail("assessment.judged", "the case has no assessment block: the session has no verdict to file");
    s.passed = rd.boolean(rd.member(a, "assessment", "passed"), "assessment.passed");
    s.completionTime_s =
        rd.numberOrNone(rd.member(a, "assessment", "completion_time_s"), "assessment.completion_time_s");
    if (s.completionTime_s && *s.completionTime_s < 0) rd.fail("assessment.completion_time_s", "must not be negative");
    const json& ms = rd.member(a, "assessment", "metrics");
    if (!ms.is_array()) rd.fail("assessment.metrics", "must be an array");
    std::set<std::string> names;
    for (size_t i = 0; i < ms.size(); ++i) {
        const std::string f = "assessment.metrics[" + std::to_string(i) + "]";
        s.metrics.push_back(readMetric(rd, ms[i], f));
        if (!names.insert(s.metrics.back().name).second)
            rd.fail(f + ".name", "'" + s.metrics.back().name + "' is given twice");
    }
    return s;
}

SessionRecord readSessionRecordFile(const std::filesystem::path& reportPath) {
    const std::string text = readFile(reportPath);
    const json doc = parseReportText(text, reportPath.string());
    SessionRecord s = readSessionRecord(doc, reportPath.string());
    s.reportSha256 = sha256Hex(text);
    return s;
}

std::string sha256Hex(const std::string& bytes) {
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    if (EVP_Digest(bytes.data(), bytes.size(), md, &n, EVP_sha256(), nullptr) != 1)
        throw std::runtime_error("sha256Hex(): EVP_Digest failed");
    static const char* digits = "0123456789abcdef";
    std::string out;
    for (unsigned int i = 0; i < n; ++i) {
        out += digits[md[i] >> 4];
        out += digits[md[i] & 15];
    }
    return out;
}

} // namespace viscera::player
