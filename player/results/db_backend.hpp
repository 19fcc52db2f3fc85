#pragma once
/// Private to the results library: the SQL connection behind ResultsDb, SQLite (libsqlite3) or
/// PostgreSQL (libpq). Statements use $1, $2 … placeholders, the same text for both; values
/// travel as text parameters (never built into the SQL), NULL as an empty optional.
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace viscera::player::detail {

using SqlValue = std::optional<std::string>;
using SqlRow = std::vector<SqlValue>;

class DbBackend {
public:
    virtual ~DbBackend() = default;
    /// Runs one statement with its parameters; returns the rows (columns as text, a REAL with 17
    /// significant digits). Throws std::runtime_error "<where>: <the server's message>".
    virtual std::vector<SqlRow> exec(const std::string& sql, const std::vector<SqlValue>& params = {}) = 0;
    /// Begins a write transaction (SQLite: BEGIN IMMEDIATE, so two writers queue, never deadlock).
    virtual void begin() = 0;
    /// The column type of an auto-numbered primary key.
    virtual const char* idColumn() const = 0;
    /// What messages call the database (the file, or the PostgreSQL database name).
    virtual std::string name() const = 0;
};

/// True when `spec` is a libpq connection string: postgresql:… / postgres:… URIs, or key=value
/// conninfo naming host= or dbname=.
bool isPostgresSpec(const std::string& spec);

/// Opens the database `spec` (a SQLite file, or a PostgreSQL conninfo). `mustExist`: a SQLite
/// file that is not there is refused (viscera::InputError) instead of created.
std::unique_ptr<DbBackend> openBackend(const std::string& spec, bool mustExist);

std::unique_ptr<DbBackend> openSqlite(const std::string& path, bool mustExist);
std::unique_ptr<DbBackend> openPostgres(const std::string& conninfo);

} // namespace viscera::player::detail
