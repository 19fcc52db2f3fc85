#include "results/results_db.hpp"

#include "results/db_backend.hpp"

#include "sim/util/error.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <stdexcept>

namespace viscera::player {

namespace {

constexpr int kDbSchemaVersion = 1;
using detail::SqlRow;
using detail::SqlValue;

SqlValue text(const std::string& s) {
    return s;
}
SqlValue real(const std::optional<double>& v) {
    if (!v) return std::nullopt;
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", *v);
    return std::string(buf);
}
SqlValue flag(bool b) {
    return std::string(b ? "1" : "0");
}
SqlValue flag(const std::optional<bool>& b) {
    return b ? flag(*b) : std::nullopt;
}
std::optional<double> toReal(const SqlValue& v) {
    return v ? std::optional<double>(std::strtod(v->c_str(), nullptr)) : std::nullopt;
}
std::optional<bool> toFlag(const SqlValue& v) {
    return v ? std::optional<bool>(*v != "0" && *v != "f") : std::nullopt;
}
std::string toText(const SqlValue& v) {
    return v.value_or("");
}

std::string nowUtc() {
    const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

const char* kSessionColumns = "s.id, s.trainee, s.case_id, s.case_version, s.package_sha256, s.player_version, "
                              "s.started_utc, s.passed, s.completion_time_s, s.report_sha256, s.source";
const char* kFilter = " WHERE (CAST($1 AS TEXT) = '' OR s.trainee = $1) AND (CAST($2 AS TEXT) = '' OR s.case_id = $2)";

SessionRecord sessionOf(const SqlRow& r) {
    SessionRecord s;
    s.id = std::stoll(toText(r[0]));
    s.trainee = toText(r[1]);
    s.caseId = toText(r[2]);
    s.caseVersion = toText(r[3]);
    s.packageSha256 = toText(r[4]);
    s.playerVersion = toText(r[5]);
    s.startedUtc = toText(r[6]);
    s.passed = toFlag(r[7]).value_or(false);
    s.completionTime_s = toReal(r[8]);
    s.reportSha256 = toText(r[9]);
    s.origin = toText(r[10]);
    return s;
}

MetricRecord metricOf(const SqlRow& r) {
    MetricRecord m;
    m.name = toText(r[1]);
    m.unit = toText(r[2]);
    m.value = toReal(r[3]);
    m.lowerIsBetter = toText(r[4]) != "higher";
    m.limit = toReal(r[5]);
    m.passed = toFlag(r[6]).value_or(false);
    if (r[7] && r[8] && r[9]) m.expert = ExpertLevel{*toReal(r[7]), *toReal(r[8]), *toReal(r[9])};
    m.withinExpert = toFlag(r[10]);
    return m;
}

} // namespace

std::string defaultResultsDb() {
    const char* xdg = std::getenv("XDG_DATA_HOME");
    if (xdg && *xdg) return std::string(xdg) + "/viscera/results.sqlite";
    const char* home = std::getenv("HOME");
    if (!home || !*home) throw InputError("--db: neither XDG_DATA_HOME nor HOME is set; name the database with --db");
    return std::string(home) + "/.local/share/viscera/results.sqlite";
}

ResultsDb::ResultsDb(std::unique_ptr<detail::DbBackend> backend) : m_db(std::move(backend)) {}
ResultsDb::~ResultsDb() = default;

std::unique_ptr<ResultsDb> ResultsDb::open(const std::string& spec, bool mustExist) {
    std::unique_ptr<ResultsDb> db(new ResultsDb(detail::openBackend(spec, mustExist)));
    db->createSchema();
    return db;
}

std::string ResultsDb::name() const {
    return m_db->name();
}

void ResultsDb::createSchema() {
    m_db->begin();
    try {
        m_db->exec("CREATE TABLE IF NOT EXISTS schema_version (version INTEGER NOT NULL)");
        m_db->exec(std::string("CREATE TABLE IF NOT EXISTS sessions (id ") + m_db->idColumn() +
                   ", trainee TEXT NOT NULL, case_id TEXT NOT NULL, case_version TEXT NOT NULL, "
                   "package_sha256 TEXT NOT NULL, player_version TEXT NOT NULL, started_utc TEXT NOT NULL, "
                   "passed INTEGER NOT NULL, completion_time_s DOUBLE PRECISION, report_sha256 TEXT NOT NULL UNIQUE, "
                   "source TEXT NOT NULL, added_utc TEXT NOT NULL)");
        m_db->exec("CREATE TABLE IF NOT EXISTS metrics (session_id BIGINT NOT NULL REFERENCES sessions(id) ON DELETE "
                   "CASCADE, position INTEGER NOT NULL, name TEXT NOT NULL, unit TEXT NOT NULL, value DOUBLE "
                   "PRECISION, better TEXT NOT NULL, limit_value DOUBLE PRECISION, passed INTEGER NOT NULL, "
                   "expert_mean DOUBLE PRECISION, expert_sd DOUBLE PRECISION, expert_bound DOUBLE PRECISION, "
                   "within_expert INTEGER, PRIMARY KEY (session_id, name))");
        m_db->exec("CREATE INDEX IF NOT EXISTS sessions_trainee_case ON sessions (trainee, case_id, started_utc)");
        const auto v = m_db->exec("SELECT MAX(version) FROM schema_version");
        if (v.empty() || !v[0][0]) {
            m_db->exec("INSERT INTO schema_version (version) VALUES ($1)", {std::to_string(kDbSchemaVersion)});
        } else if (std::stoi(*v[0][0]) > kDbSchemaVersion) {
            throw InputError(m_db->name() + ": results database schema " + *v[0][0] +
                             " is newer than this program reads (" + std::to_string(kDbSchemaVersion) + ")");
        }
        m_db->exec("COMMIT");
    } catch (...) {
        try { // a lost connection must not replace the error that stopped the schema
            m_db->exec("ROLLBACK");
        } catch (...) {
        }
        throw;
    }
}

AddOutcome ResultsDb::add(const SessionRecord& s) {
    if (s.reportSha256.empty())
        throw std::invalid_argument("player::ResultsDb::add(): the session has no report_sha256");
    m_db->begin();
    try {
        const auto had = m_db->exec("SELECT id FROM sessions WHERE report_sha256 = $1", {s.reportSha256});
        if (!had.empty()) {
            m_db->exec("ROLLBACK");
            return {std::stoll(*had[0][0]), false};
        }
        const auto id = m_db->exec(
            "INSERT INTO sessions (trainee, case_id, case_version, package_sha256, player_version, started_utc, "
            "passed, completion_time_s, report_sha256, source, added_utc) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, "
            "$9, $10, $11) RETURNING id",
            {s.trainee, s.caseId, s.caseVersion, s.packageSha256, s.playerVersion, s.startedUtc, flag(s.passed),
             real(s.completionTime_s), s.reportSha256, s.origin, nowUtc()});
        const std::string sid = *id.at(0).at(0);
        for (size_t i = 0; i < s.metrics.size(); ++i) {
            const MetricRecord& m = s.metrics[i];
            const auto e = m.expert;
            m_db->exec("INSERT INTO metrics (session_id, position, name, unit, value, better, limit_value, passed, "
                       "expert_mean, expert_sd, expert_bound, within_expert) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, "
                       "$9, $10, $11, $12)",
                       {sid, std::to_string(i), m.name, m.unit, real(m.value),
                        text(m.lowerIsBetter ? "lower" : "higher"), real(m.limit), flag(m.passed),
                        real(e ? std::optional(e->mean) : std::nullopt), real(e ? std::optional(e->sd) : std::nullopt),
                        real(e ? std::optional(e->bound) : std::nullopt), flag(m.withinExpert)});
        }
        m_db->exec("COMMIT");
        return {std::stoll(sid), true};
    } catch (...) {
        try {
            m_db->exec("ROLLBACK");
        } catch (...) {
        }
        throw;
    }
}

std::vector<SessionRecord> ResultsDb::sessions(const SessionFilter& f) {
    const std::vector<SqlValue> params{f.trainee, f.caseId};
    std::vector<SessionRecord> out;
    std::map<int64_t, size_t> index;
    for (const SqlRow& r : m_db->exec(std::string("SELECT ") + kSessionColumns + " FROM sessions s" + kFilter +
                                          " ORDER BY s.trainee, s.case_id, s.started_utc, s.id",
                                      params)) {
        out.push_back(sessionOf(r));
        index[out.back().id] = out.size() - 1;
    }
    for (const SqlRow& r : m_db->exec(
             std::string("SELECT m.session_id, m.name, m.unit, m.value, m.better, m.limit_value, m.passed, "
                         "m.expert_mean, m.expert_sd, m.expert_bound, m.within_expert FROM metrics m JOIN sessions s "
                         "ON s.id = m.session_id") +
                 kFilter + " ORDER BY m.session_id, m.position",
             params)) {
        const auto it = index.find(std::stoll(toText(r[0])));
        if (it != index.end()) out[it->second].metrics.push_back(metricOf(r));
    }
    return out;
}

} // namespace viscera::player
