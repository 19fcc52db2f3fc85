#include "player/results/report_generator.hpp"

#include <cstdio>
#include <fstream>
#include <optional>

namespace viscera::test {

namespace {

using nlohmann::json;

struct Spec {
    const char* name;
    const char* unit;
    bool lower;
    std::optional<double> limit;
    std::optional<double> mean, sd;
};

const Spec kSpecs[] = {{"completion_time_s", "s", true, 60.0, 10.0, 2.0},
                       {"path_length_m", "m", true, std::nullopt, 0.8, 0.1},
                       {"cut_coverage", "fraction", false, 0.5, 0.9, 0.03},
                       {"force_max_n", "N", true, 5.0, std::nullopt, std::nullopt}};

json metric(const Spec& s, std::optional<double> value) {
    json m{{"name", s.name}, {"unit", s.unit}, {"better", s.lower ? "lower" : "higher"}};
    m["value"] = value ? json(*value) : json(nullptr);
    m["limit"] = s.limit ? json(*s.limit) : json(nullptr);
    m["passed"] = !s.limit || (value && (s.lower ? *value <= *s.limit : *value >= *s.limit));
    if (s.mean) {
        const double bound = s.lower ? *s.mean + 2 * *s.sd : *s.mean - 2 * *s.sd;
        m["expert"] = {{"mean", *s.mean}, {"sd", *s.sd}, {"bound", bound}};
        m["within_expert"] = value ? json(s.lower ? *value <= bound : *value >= bound) : json(nullptr);
    } else {
        m["expert"] = nullptr;
        m["within_expert"] = nullptr;
    }
    return m;
}

json report(const std::string& trainee, int attempt, const std::optional<double> (&values)[4]) {
    char started[32];
    std::snprintf(started, sizeof started, "2026-11-%02dT09:%02d:00Z", attempt, 10 + attempt);
    json metrics = json::array();
    bool passed = true;
    for (int i = 0; i < 4; ++i) {
        metrics.push_back(metric(kSpecs[i], values[i]));
        passed = passed && metrics.back()["passed"].get<bool>();
    }
    return {{"schemaVersion", 5},
            {"case", {{"id", "rectum"}, {"version", "1.2.0"}}},
            {"record",
             {{"trainee", trainee},
              {"started_utc", started},
              {"player_version", "0.1.0"},
              {"case_id", "rectum"},
              {"case_version", "1.2.0"},
              {"package_sha256", std::string(64, 'a')}}},
            {"assessment",
             {{"passed", passed},
              {"completion_time_s", values[0] ? json(*values[0]) : json(nullptr)},
              {"metrics", metrics}}}};
}

} // namespace

json improvingReport(const std::string& trainee, int attempt) {
    static const double time[] = {70, 32, 26, 21, 17, 13, 12, 11.5, 11, 10.5, 10.2, 10.1};
    static const double path[] = {2.0, 1.8, 1.6, 1.4, 1.2, 0.95, 0.9, 0.85, 0.82, 0.8, 0.79, 0.78};
    static const double clip[] = {0.55, 0.45, 0.68, 0.74, 0.8, 0.86, 0.88, 0.9, 0.91, 0.92, 0.92, 0.93};
    const int i = std::min(attempt, 12) - 1;
    const std::optional<double> v[4] = {time[i], path[i], clip[i], 3.0 - 0.1 * i};
    return report(trainee, attempt, v);
}

json strugglingReport(const std::string& trainee, int attempt) {
    const bool good = attempt % 2 == 0;
    std::optional<double> time = good ? 12.0 : 30.0;
    if (attempt == 3) time.reset();
    const std::optional<double> v[4] = {time, good ? 0.9 : 1.5, good ? 0.88 : 0.7, 4.0};
    return report(trainee, attempt, v);
}

std::vector<std::filesystem::path> writeReports(const std::filesystem::path& dir, const std::string& trainee, int n,
                                                bool improving) {
    std::vector<std::filesystem::path> out;
    for (int a = 1; a <= n; ++a) {
        const auto p = dir / (trainee + "-" + std::to_string(a) + ".json");
        std::ofstream(p) << (improving ? improvingReport(trainee, a) : strugglingReport(trainee, a)).dump(2);
        out.push_back(p);
    }
    return out;
}

} // namespace viscera::test
