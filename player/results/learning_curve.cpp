#include "results/learning_curve.hpp"

#include <algorithm>
#include <map>
#include <tuple>

namespace viscera::player {

namespace {

Attempt assess(const SessionRecord& s, int number) {
    Attempt a;
    a.number = number;
    a.session = &s;
    for (const MetricRecord& m : s.metrics) {
        if (!m.expert) continue;
        ++a.expertMetrics;
        if (m.withinExpert.value_or(false)) ++a.withinExpert;
    }
    a.atExpertLevel = s.passed && a.expertMetrics > 0 && a.withinExpert == a.expertMetrics;
    return a;
}

} // namespace

std::vector<LearningCurve> learningCurves(const std::vector<SessionRecord>& sessions) {
    std::map<std::pair<std::string, std::string>, std::vector<const SessionRecord*>> groups;
    for (const SessionRecord& s : sessions)
        groups[{s.trainee, s.caseId}].push_back(&s);
    std::vector<LearningCurve> out;
    for (auto& [key, list] : groups) {
        std::stable_sort(list.begin(), list.end(), [](const SessionRecord* a, const SessionRecord* b) {
            return std::tie(a->startedUtc, a->id) < std::tie(b->startedUtc, b->id);
        });
        LearningCurve c;
        c.trainee = key.first;
        c.caseId = key.second;
        for (size_t i = 0; i < list.size(); ++i) {
            c.attempts.push_back(assess(*list[i], static_cast<int>(i) + 1));
            if (!c.proficientAt && i > 0 && c.attempts[i].atExpertLevel && c.attempts[i - 1].atExpertLevel)
                c.proficientAt = c.attempts[i].number;
        }
        out.push_back(std::move(c));
    }
    return out;
}

std::string LearningCurve::verdict() const {
    if (proficientAt) return "proficient at attempt " + std::to_string(*proficientAt);
    if (attempts.empty()) return "not yet proficient (no attempt)";
    const Attempt& last = attempts.back();
    std::string why;
    if (last.expertMetrics == 0)
        why = "attempt " + std::to_string(last.number) + " has no metric with an expert level";
    else if (last.atExpertLevel)
        why = "attempt " + std::to_string(last.number) + " at expert level; one more in a row needed";
    else
        why = "attempt " + std::to_string(last.number) + ": " + std::to_string(last.withinExpert) + " of " +
              std::to_string(last.expertMetrics) + " metrics within the expert level" +
              (last.session->passed ? "" : ", not passed");
    return "not yet proficient (" + why + ")";
}

} // namespace viscera::player
