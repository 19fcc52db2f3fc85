// viscera-results: the trainee results database on the command line (add, list, progress,
// instructor, export). Exit 0 on success, 2 on bad input (a malformed report, a bad option, an
// unwritable output), 1 when the database itself fails.
#include "plots/html_text.hpp"
#include "results/expert_levels.hpp"
#include "results/instructor_view.hpp"
#include "results/learning_curve.hpp"
#include "results/progress_page.hpp"
#include "results/results_db.hpp"
#include "results/results_export.hpp"
#include "results/session_record.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace viscera;
using namespace viscera::player;

const char* kUsage =
    "usage: viscera-results <command> [options]\n"
    "  add REPORT.json... [--db D]                       add session reports (each atomically)\n"
    "  list [--trainee T] [--case C] [--db D]            the sessions, numbered per trainee and case\n"
    "  progress --trainee T [--case C] -o DIR [--db D]   learning curves: DIR/<metric>.png, DIR/progress.html\n"
    "  instructor [--case C] [-o page.html] [--db D]     every trainee per case: attempts, passes, proficiency\n"
    "  export [--format csv|json] [-o FILE] [--db D]     every session with its metrics (stdout without -o)\n"
    "  expert-levels --case C --trainee E1,E2... [-o levels.json] [--db D]\n"
    "                                                    expert levels (mean, sd) from the experts' sessions,\n"
    "                                                    for the studio's Assessment dock (Import expert levels)\n"
    "  --help, --version\n"
    "D: a SQLite file (default $XDG_DATA_HOME/viscera/results.sqlite or ~/.local/share/viscera/results.sqlite)\n"
    "   or a PostgreSQL connection (postgresql://user@host/db, or \"host=... dbname=...\").\n"
    "Proficient: two consecutive passed attempts with every expert-levelled metric within its level.\n";

struct Args {
    std::string command;
    std::vector<std::string> positional;
    std::map<std::string, std::string> options; ///< --db, --trainee, --case, -o, --format
};

Args parse(int argc, char** argv) {
    Args a;
    a.command = argv[1];
    static const std::map<std::string, std::set<std::string>> allowed{
        {"add", {"--db"}},
        {"list", {"--db", "--trainee", "--case"}},
        {"progress", {"--db", "--trainee", "--case", "-o"}},
        {"instructor", {"--db", "--case", "-o"}},
        {"export", {"--db", "--format", "-o"}},
        {"expert-levels", {"--db", "--case", "--trainee", "-o"}}};
    const auto it = allowed.find(a.command);
    if (it == allowed.end()) throw InputError("'" + a.command + "': unknown command (see viscera-results --help)");
    for (int i = 2; i < argc; ++i) {
        const std::string s = argv[i];
        if (s.size() > 1 && s[0] == '-') {
            if (!it->second.count(s)) throw InputError(a.command + ": " + s + ": unknown option");
            if (i + 1 >= argc) throw InputError(a.command + ": " + s + ": needs a value");
            if (a.options.count(s)) throw InputError(a.command + ": " + s + ": given twice");
            a.options[s] = argv[++i];
        } else {
            if (a.command != "add") throw InputError(a.command + ": '" + s + "': unexpected argument");
            a.positional.push_back(s);
        }
    }
    return a;
}

std::string option(const Args& a, const std::string& key) {
    const auto it = a.options.find(key);
    return it == a.options.end() ? std::string() : it->second;
}

std::unique_ptr<ResultsDb> openDb(const Args& a, bool mustExist) {
    const std::string spec = a.options.count("--db") ? option(a, "--db") : defaultResultsDb();
    return ResultsDb::open(spec, mustExist);
}

std::string describe(const SessionRecord& s) {
    return s.trainee + " " + s.caseId + " " + s.caseVersion + ", " + s.startedUtc + ", " +
           (s.passed ? "passed" : "not passed") +
           (s.completionTime_s ? formatNumber(", %.1f s", *s.completionTime_s) : std::string(", not completed"));
}

int add(const Args& a) {
    if (a.positional.empty()) throw InputError("add: name at least one session report (REPORT.json)");
    std::vector<SessionRecord> records; // every report is read before any is added
    for (const std::string& p : a.positional)
        records.push_back(readSessionRecordFile(p));
    auto db = openDb(a, false);
    for (const SessionRecord& s : records) {
        const AddOutcome o = db->add(s);
        if (o.added)
            std::printf("%s: added session %lld: %s\n", s.origin.c_str(), static_cast<long long>(o.id),
                        describe(s).c_str());
        else
            std::printf("%s: already in the database as session %lld, not added again\n", s.origin.c_str(),
                        static_cast<long long>(o.id));
    }
    return 0;
}

int list(const Args& a) {
    auto db = openDb(a, true);
    const auto sessions = db->sessions({option(a, "--trainee"), option(a, "--case")});
    std::fputs(sessionTable(learningCurves(sessions)).c_str(), stdout);
    return 0;
}

int progress(const Args& a) {
    const std::string trainee = option(a, "--trainee"), dir = option(a, "-o");
    if (trainee.empty()) throw InputError("progress: --trainee: is required");
    if (dir.empty()) throw InputError("progress: -o: is required (the folder for the charts and progress.html)");
    requireWritableFolder(dir);
    auto db = openDb(a, true);
    const auto sessions = db->sessions({trainee, option(a, "--case")});
    const auto curves = learningCurves(sessions);
    if (curves.empty())
        throw InputError("progress: --trainee: no session of '" + trainee + "'" +
                         (option(a, "--case").empty() ? "" : " on case '" + option(a, "--case") + "'") + " in " +
                         db->name());
    if (curves.size() > 1) {
        std::string cases;
        for (const auto& c : curves)
            cases += (cases.empty() ? "" : ", ") + c.caseId;
        throw InputError("progress: --case: '" + trainee + "' has sessions of several cases (" + cases + "): name one");
    }
    const ProgressFiles files = writeProgress(curves[0], dir);
    std::printf("%s on %s: %zu attempts, %s\n", trainee.c_str(), curves[0].caseId.c_str(), curves[0].attempts.size(),
                curves[0].verdict().c_str());
    std::printf("wrote %zu chart(s) and %s\n", files.images.size(), files.page.string().c_str());
    return 0;
}

int instructor(const Args& a) {
    const std::string page = option(a, "-o");
    if (!page.empty()) requireWritableFile(page, "the instructor page");
    auto db = openDb(a, true);
    const auto sessions = db->sessions({"", option(a, "--case")});
    const auto rows = summarize(learningCurves(sessions));
    std::fputs(instructorText(rows).c_str(), stdout);
    if (!page.empty()) {
        writeFileAtomic(page, instructorHtml(rows));
        std::printf("wrote %s\n", page.c_str());
    }
    return 0;
}

int exportAll(const Args& a) {
    const std::string format = a.options.count("--format") ? option(a, "--format") : "csv";
    if (format != "csv" && format != "json") throw InputError("export: --format: must be csv or json");
    const std::string out = option(a, "-o");
    if (!out.empty()) requireWritableFile(out, "the export");
    auto db = openDb(a, true);
    const auto sessions = db->sessions();
    const auto curves = learningCurves(sessions);
    const std::string text = format == "csv" ? exportCsv(curves) : exportJson(curves);
    if (out.empty())
        std::fputs(text.c_str(), stdout);
    else
        writeFileAtomic(out, text);
    return 0;
}

/// Expert levels of a case from its experts' sessions (--trainee: a comma-separated list).
int expertLevels(const Args& a) {
    const std::string caseId = option(a, "--case"), out = option(a, "-o");
    if (caseId.empty()) throw InputError("expert-levels: --case: is required");
    std::vector<std::string> experts;
    for (size_t p = 0, q; p <= option(a, "--trainee").size(); p = q + 1) {
        q = option(a, "--trainee").find(',', p);
        if (q == std::string::npos) q = option(a, "--trainee").size();
        if (q > p) experts.push_back(option(a, "--trainee").substr(p, q - p));
    }
    if (experts.empty()) throw InputError("expert-levels: --trainee: name the experts (E1,E2,...)");
    for (size_t i = 0; i < experts.size(); ++i)
        for (size_t j = 0; j < i; ++j)
            if (experts[i] == experts[j])
                throw InputError("expert-levels: --trainee: '" + experts[i] + "' is named twice");
    if (!out.empty()) requireWritableFile(out, "the expert levels");
    auto db = openDb(a, true);
    std::vector<SessionRecord> sessions;
    for (const std::string& e : experts) {
        const auto s = db->sessions({e, caseId});
        if (s.empty()) throw InputError("expert-levels: --trainee: no session of '" + e + "' on case '" + caseId + "'");
        sessions.insert(sessions.end(), s.begin(), s.end());
    }
    for (const SessionRecord& s : sessions) // one version of the case: its metrics mean one thing
        if (s.caseVersion != sessions.front().caseVersion)
            throw InputError("expert-levels: --case: the experts' sessions ran versions " +
                             sessions.front().caseVersion + " and " + s.caseVersion + " of '" + caseId +
                             "'; levels need one version");
    const auto levels = deriveExpertLevels(sessions);
    // The table to the terminal; without -o the JSON alone goes to standard output (redirectable).
    std::FILE* table = out.empty() ? stderr : stdout;
    for (const DerivedLevel& l : levels)
        std::fprintf(table, "%-24s n %-3d mean %-12s sd %s %s\n", l.name.c_str(), l.n,
                     formatNumber("%.4g", l.mean).c_str(), formatNumber("%.4g", l.sd).c_str(), l.unit.c_str());
    const std::string text = expertLevelsJson(caseId, experts, sessions.size(), levels);
    if (out.empty())
        std::fputs(text.c_str(), stdout);
    else {
        writeFileAtomic(out, text);
        std::printf("wrote %s (%zu metrics from %zu sessions)\n", out.c_str(), levels.size(), sessions.size());
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fputs(kUsage, stderr);
        return 2;
    }
    const std::string first = argv[1];
    if (first == "--help" || first == "-h") {
        std::fputs(kUsage, stdout);
        return 0;
    }
    if (first == "--version") {
        std::printf("viscera-results %s\n", VISCERA_VERSION);
        return 0;
    }
    try {
        const Args a = parse(argc, argv);
        if (a.command == "add") return add(a);
        if (a.command == "list") return list(a);
        if (a.command == "progress") return progress(a);
        if (a.command == "instructor") return instructor(a);
        if (a.command == "expert-levels") return expertLevels(a);
        return exportAll(a);
    } catch (const InputError& e) {
        std::fprintf(stderr, "viscera-results: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "viscera-results: %s\n", e.what());
        return 1;
    }
}
