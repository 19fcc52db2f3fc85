#include "results/instructor_view.hpp"

#include "plots/html_text.hpp"

#include <algorithm>
#include <cstdio>
#include <tuple>

namespace viscera::player {

namespace {

std::string seconds(const std::optional<double>& v) {
    return v ? formatNumber("%.1f s", *v) : "—";
}

std::string proficiency(const std::optional<int>& at) {
    return at ? "at attempt " + std::to_string(*at) : "not yet";
}

std::string padded(const std::string& s, size_t width) {
    // Display width: count UTF-8 lead bytes only (the em dash is one column).
    size_t cols = 0;
    for (unsigned char c : s)
        if ((c & 0xC0) != 0x80) ++cols;
    return s + std::string(width > cols ? width - cols : 0, ' ');
}

} // namespace

std::vector<TraineeSummary> summarize(const std::vector<LearningCurve>& curves) {
    std::vector<TraineeSummary> rows;
    for (const LearningCurve& c : curves) {
        TraineeSummary r;
        r.caseId = c.caseId;
        r.trainee = c.trainee;
        r.attempts = static_cast<int>(c.attempts.size());
        r.proficientAt = c.proficientAt;
        for (const Attempt& a : c.attempts) {
            if (a.session->passed) ++r.passes;
            const auto& t = a.session->completionTime_s;
            if (t && (!r.bestCompletion_s || *t < *r.bestCompletion_s)) r.bestCompletion_s = t;
        }
        rows.push_back(r);
    }
    std::stable_sort(rows.begin(), rows.end(), [](const TraineeSummary& a, const TraineeSummary& b) {
        return std::tie(a.caseId, a.trainee) < std::tie(b.caseId, b.trainee);
    });
    return rows;
}

std::string instructorText(const std::vector<TraineeSummary>& rows) {
    if (rows.empty()) return "no sessions\n";
    std::string out, current;
    bool first = true;
    for (const TraineeSummary& r : rows) {
        if (first || r.caseId != current) {
            current = r.caseId;
            out += std::string(first ? "" : "\n") + "case " + r.caseId + "\n  " + padded("trainee", 16) +
                   padded("attempts", 10) + padded("passes", 8) + padded("best time", 12) + "proficient\n";
            first = false;
        }
        out += "  " + padded(r.trainee, 16) + padded(std::to_string(r.attempts), 10) +
               padded(std::to_string(r.passes), 8) + padded(seconds(r.bestCompletion_s), 12) +
               proficiency(r.proficientAt) + "\n";
    }
    return out;
}

std::string instructorHtml(const std::vector<TraineeSummary>& rows) {
    std::string page = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>Trainee results"
                       "</title>\n<style>" +
                       std::string(kPageStyle) + "</style></head><body>\n<h1>Trainee results</h1>\n";
    if (rows.empty()) page += "<p>No sessions.</p>\n";
    std::string current;
    for (size_t i = 0; i < rows.size(); ++i) {
        const TraineeSummary& r = rows[i];
        if (i == 0 || r.caseId != current) {
            if (i > 0) page += "</table>\n";
            current = r.caseId;
            page += "<h2>Case " + htmlText(r.caseId) +
                    "</h2>\n<table><tr><th>trainee</th><th>attempts</th><th>passes</th><th>best completion time</th>"
                    "<th>proficient</th></tr>\n";
        }
        page += "<tr><td>" + htmlText(r.trainee) + "</td><td>" + std::to_string(r.attempts) + "</td><td>" +
                std::to_string(r.passes) + "</td><td>" + seconds(r.bestCompletion_s) + "</td><td class=\"" +
                (r.proficientAt ? "ok" : "bad") + "\">" + proficiency(r.proficientAt) + "</td></tr>\n";
    }
    if (!rows.empty()) page += "</table>\n";
    return page + "<p class=\"foot\">Made by viscera-results " VISCERA_VERSION ".</p>\n</body></html>\n";
}

std::string sessionTable(const std::vector<LearningCurve>& curves) {
    if (curves.empty()) return "no sessions\n";
    std::string out = padded("trainee", 14) + padded("case", 14) + padded("attempt", 9) + padded("started (UTC)", 22) +
                      padded("passed", 8) + padded("time", 11) + padded("expert", 9) + "proficient\n";
    for (const LearningCurve& c : curves)
        for (const Attempt& a : c.attempts) {
            const SessionRecord& s = *a.session;
            const bool proficient = c.proficientAt && a.number >= *c.proficientAt;
            out += padded(s.trainee, 14) + padded(s.caseId, 14) + padded(std::to_string(a.number), 9) +
                   padded(s.startedUtc, 22) + padded(s.passed ? "yes" : "no", 8) +
                   padded(seconds(s.completionTime_s), 11) +
                   padded(std::to_string(a.withinExpert) + "/" + std::to_string(a.expertMetrics), 9) +
                   (proficient ? "yes" : "no") + "\n";
        }
    return out;
}

} // namespace viscera::player
