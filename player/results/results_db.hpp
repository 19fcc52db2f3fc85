#pragma once
/// The trainee results database: every assessed session of every trainee, SQLite (a file, by
/// default) or PostgreSQL (a training centre's server), the same schema in both.
///
/// Tables: schema_version(version); sessions(id, trainee, case_id, case_version, package_sha256,
/// player_version, started_utc, passed, completion_time_s, report_sha256 UNIQUE, source,
/// added_utc); metrics(session_id → sessions.id, position, name, unit, value, better,
/// limit_value, passed, expert_mean, expert_sd, expert_bound, within_expert). Made on first use.
#include "results/session_record.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::player {

namespace detail {
class DbBackend;
}

/// The default database: $XDG_DATA_HOME/viscera/results.sqlite, or
/// ~/.local/share/viscera/results.sqlite.
std::string defaultResultsDb();

struct SessionFilter {
    std::string trainee, caseId; ///< empty: any
};

struct AddOutcome {
    int64_t id = 0;
    bool added = false; ///< false: the same report was already there (session `id`)
};

class ResultsDb {
public:
    /// Opens (and on first use makes) the database `spec`: a SQLite file path, or a libpq
    /// conninfo (postgresql://…, postgres://…, "host=… dbname=…"). `mustExist`: a SQLite file that
    /// is not there is refused, viscera::InputError. A database of a newer schema is refused.
    static std::unique_ptr<ResultsDb> open(const std::string& spec, bool mustExist = false);
    ~ResultsDb();
    ResultsDb(const ResultsDb&) = delete;
    ResultsDb& operator=(const ResultsDb&) = delete;

    /// Adds one session with its metrics in one transaction; the same report (by sha256 of its
    /// bytes) added again is not stored twice.
    AddOutcome add(const SessionRecord& session);
    /// The sessions matching `filter`, with their metrics, ordered by trainee, case, start time, id.
    std::vector<SessionRecord> sessions(const SessionFilter& filter = {});
    /// "results.sqlite" or "PostgreSQL database centre", for messages.
    std::string name() const;

private:
    explicit ResultsDb(std::unique_ptr<detail::DbBackend> backend);
    void createSchema();
    std::unique_ptr<detail::DbBackend> m_db;
};

} // namespace viscera::player
