// The SQLite backend (libsqlite3, the C API).
#include "results/db_backend.hpp"

#include "sim/util/error.hpp"

#include <sqlite3.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace viscera::player::detail {

namespace {

class SqliteBackend final : public DbBackend {
public:
    explicit SqliteBackend(const std::string& path) : m_path(path) {
        const int rc = sqlite3_open_v2(path.c_str(), &m_db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
        if (rc != SQLITE_OK) {
            const std::string why = m_db ? sqlite3_errmsg(m_db) : sqlite3_errstr(rc);
            sqlite3_close(m_db);
            m_db = nullptr;
            throw InputError(path + ": cannot open the results database (" + why + ")");
        }
        sqlite3_busy_timeout(m_db, 10000);
        exec("PRAGMA foreign_keys = ON", {});
    }
    ~SqliteBackend() override { sqlite3_close(m_db); }
    SqliteBackend(const SqliteBackend&) = delete;
    SqliteBackend& operator=(const SqliteBackend&) = delete;

    std::vector<SqlRow> exec(const std::string& sql, const std::vector<SqlValue>& params) override {
        sqlite3_stmt* st = nullptr;
        if (sqlite3_prepare_v2(m_db, sql.c_str(), -1, &st, nullptr) != SQLITE_OK) fail();
        struct Finalize {
            sqlite3_stmt* s;
            ~Finalize() { sqlite3_finalize(s); }
        } finalize{st};
        for (size_t i = 0; i < params.size(); ++i) {
            std::string name = "$";
            name += std::to_string(i + 1);
            const int idx = sqlite3_bind_parameter_index(st, name.c_str());
            if (idx == 0) continue; // a parameter the statement does not use
            const int rc = params[i] ? sqlite3_bind_text(st, idx, params[i]->c_str(), -1, SQLITE_TRANSIENT)
                                     : sqlite3_bind_null(st, idx);
            if (rc != SQLITE_OK) fail();
        }
        std::vector<SqlRow> rows;
        for (;;) {
            const int rc = sqlite3_step(st);
            if (rc == SQLITE_DONE) break;
            if (rc != SQLITE_ROW) fail();
            SqlRow row;
            for (int c = 0; c < sqlite3_column_count(st); ++c)
                row.push_back(column(st, c));
            rows.push_back(std::move(row));
        }
        return rows;
    }
    void begin() override { exec("BEGIN IMMEDIATE", {}); }
    const char* idColumn() const override { return "INTEGER PRIMARY KEY"; }
    std::string name() const override { return m_path; }

private:
    static SqlValue column(sqlite3_stmt* st, int c) {
        switch (sqlite3_column_type(st, c)) {
        case SQLITE_NULL:
            return std::nullopt;
        case SQLITE_FLOAT: {
            char buf[40];
            std::snprintf(buf, sizeof buf, "%.17g", sqlite3_column_double(st, c));
            return std::string(buf);
        }
        default:
            return std::string(reinterpret_cast<const char*>(sqlite3_column_text(st, c)));
        }
    }
    [[noreturn]] void fail() const { throw std::runtime_error(m_path + ": " + sqlite3_errmsg(m_db)); }

    std::string m_path;
    sqlite3* m_db = nullptr;
};

} // namespace

std::unique_ptr<DbBackend> openSqlite(const std::string& path, bool mustExist) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (mustExist && !fs::exists(path, ec))
        throw InputError(path + ": no results database here yet (add a session report first: viscera-results add)");
    if (fs::is_directory(path, ec)) throw InputError(path + ": is a folder, not a results database file");
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty() && !fs::exists(parent, ec)) {
        fs::create_directories(parent, ec);
        if (ec) throw InputError(path + ": cannot create its folder (" + ec.message() + ")");
    }
    return std::make_unique<SqliteBackend>(path);
}

} // namespace viscera::player::detail
