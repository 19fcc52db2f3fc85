#include "results/results_export.hpp"

#include "plots/html_text.hpp"

#include <nlohmann/json.hpp>

namespace viscera::player {

namespace {

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string o = "\"";
    for (char c : s)
        o += c == '"' ? std::string("\"\"") : std::string(1, c);
    return o + "\"";
}

std::string csvNumber(const std::optional<double>& v) {
    return v ? formatNumber("%.17g", *v) : "";
}

std::string csvFlag(const std::optional<bool>& v) {
    return v ? (*v ? "true" : "false") : "";
}

nlohmann::json jsonNumber(const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

} // namespace

std::string exportCsv(const std::vector<LearningCurve>& curves) {
    std::string out = "session_id,trainee,case_id,case_version,attempt,started_utc,player_version,package_sha256,"
                      "passed,completion_time_s,proficient,metric,unit,value,better,limit,metric_passed,expert_mean,"
                      "expert_sd,expert_bound,within_expert\n";
    for (const LearningCurve& c : curves)
        for (const Attempt& a : c.attempts) {
            const SessionRecord& s = *a.session;
            const std::string head = std::to_string(s.id) + "," + csvField(s.trainee) + "," + csvField(s.caseId) + "," +
                                     csvField(s.caseVersion) + "," + std::to_string(a.number) + "," +
                                     csvField(s.startedUtc) + "," + csvField(s.playerVersion) + "," + s.packageSha256 +
                                     "," + csvFlag(s.passed) + "," + csvNumber(s.completionTime_s) + "," +
                                     csvFlag(c.proficientAt && a.number >= *c.proficientAt);
            if (s.metrics.empty()) out += head + ",,,,,,,,,,\n";
            for (const MetricRecord& m : s.metrics) {
                const auto e = m.expert;
                out += head + "," + csvField(m.name) + "," + csvField(m.unit) + "," + csvNumber(m.value) + "," +
                       (m.lowerIsBetter ? "lower" : "higher") + "," + csvNumber(m.limit) + "," + csvFlag(m.passed) +
                       "," + csvNumber(e ? std::optional(e->mean) : std::nullopt) + "," +
                       csvNumber(e ? std::optional(e->sd) : std::nullopt) + "," +
                       csvNumber(e ? std::optional(e->bound) : std::nullopt) + "," + csvFlag(m.withinExpert) + "\n";
            }
        }
    return out;
}

std::string exportJson(const std::vector<LearningCurve>& curves) {
    nlohmann::json all = nlohmann::json::array();
    for (const LearningCurve& c : curves)
        for (const Attempt& a : c.attempts) {
            const SessionRecord& s = *a.session;
            nlohmann::json metrics = nlohmann::json::array();
            for (const MetricRecord& m : s.metrics) {
                nlohmann::json expert = nullptr;
                if (m.expert) expert = {{"mean", m.expert->mean}, {"sd", m.expert->sd}, {"bound", m.expert->bound}};
                metrics.push_back({{"name", m.name},
                                   {"unit", m.unit},
                                   {"value", jsonNumber(m.value)},
                                   {"better", m.lowerIsBetter ? "lower" : "higher"},
                                   {"limit", jsonNumber(m.limit)},
                                   {"passed", m.passed},
                                   {"expert", expert},
                                   {"within_expert", m.withinExpert ? nlohmann::json(*m.withinExpert) : nullptr}});
            }
            all.push_back({{"session_id", s.id},
                           {"trainee", s.trainee},
                           {"case_id", s.caseId},
                           {"case_version", s.caseVersion},
                           {"attempt", a.number},
                           {"started_utc", s.startedUtc},
                           {"player_version", s.playerVersion},
                           {"package_sha256", s.packageSha256},
                           {"report_sha256", s.reportSha256},
                           {"passed", s.passed},
                           {"completion_time_s", jsonNumber(s.completionTime_s)},
                           {"proficient", bool(c.proficientAt && a.number >= *c.proficientAt)},
                           {"metrics", metrics}});
        }
    return nlohmann::json{{"sessions", all}}.dump(2) + "\n";
}

} // namespace viscera::player
