#include "results/expert_levels.hpp"

#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace viscera::player {

std::vector<DerivedLevel> deriveExpertLevels(const std::vector<SessionRecord>& sessions) {
    if (sessions.size() < 2)
        throw InputError("expert-levels: " + std::to_string(sessions.size()) +
                         " expert session(s): a mean and a standard deviation need at least 2");
    std::vector<DerivedLevel> levels;
    std::vector<std::vector<double>> values;
    for (const SessionRecord& s : sessions)
        for (const MetricRecord& m : s.metrics) {
            if (!m.value || !std::isfinite(*m.value)) continue;
            size_t k = 0;
            while (k < levels.size() && levels[k].name != m.name)
                ++k;
            if (k == levels.size()) {
                levels.push_back({m.name, m.unit});
                values.emplace_back();
            }
            values[k].push_back(*m.value);
        }
    std::vector<DerivedLevel> out;
    for (size_t k = 0; k < levels.size(); ++k) {
        const std::vector<double>& v = values[k];
        if (v.size() < 2) continue;
        DerivedLevel l = levels[k];
        l.n = static_cast<int>(v.size());
        for (double x : v)
            l.mean += x / double(v.size());
        double ss = 0;
        for (double x : v)
            ss += (x - l.mean) * (x - l.mean);
        l.sd = std::sqrt(ss / double(v.size() - 1));
        out.push_back(l);
    }
    return out;
}

std::string expertLevelsJson(const std::string& caseId, const std::vector<std::string>& experts, size_t sessions,
                             const std::vector<DerivedLevel>& levels) {
    nlohmann::json doc = {{"case_id", caseId}, {"experts", experts}, {"sessions", sessions}};
    doc["metrics"] = nlohmann::json::object();
    for (const DerivedLevel& l : levels)
        doc["metrics"][l.name] = {{"expert", {{"mean", l.mean}, {"sd", l.sd}}}, {"n", l.n}};
    return doc.dump(2) + "\n";
}

} // namespace viscera::player
