#include "player/results/results_test_db.hpp"

#ifdef VISCERA_RESULTS_TEST_POSTGRES
#include <libpq-fe.h>

#include <fstream>
#include <sstream>
#include <unistd.h>
#endif

namespace viscera::test {

#ifdef VISCERA_RESULTS_TEST_POSTGRES
namespace {

std::string run(const std::string& conninfo, const std::string& sql) {
    PGconn* c = PQconnectdb(conninfo.c_str());
    std::string err;
    if (PQstatus(c) != CONNECTION_OK) {
        err = PQerrorMessage(c);
    } else {
        PGresult* r = PQexec(c, sql.c_str());
        if (PQresultStatus(r) != PGRES_COMMAND_OK) err = PQresultErrorMessage(r);
        PQclear(r);
    }
    PQfinish(c);
    return err;
}

} // namespace

TestDatabase::TestDatabase(const std::string&) {
    std::ifstream in(VISCERA_RESULTS_PG_STATE "/conninfo");
    std::getline(in, m_admin);
    if (m_admin.empty()) {
        m_error = "no PostgreSQL server: " VISCERA_RESULTS_PG_STATE "/conninfo is missing (the fixture test "
                  "results_postgres_start must run first: ctest -L postgres)";
        return;
    }
    static int counter = 0;
    m_name = "results_" + std::to_string(::getpid()) + "_" + std::to_string(++counter);
    m_error = run(m_admin, "CREATE DATABASE " + m_name);
    std::string base = m_admin;
    if (auto p = base.find("dbname="); p != std::string::npos) base.erase(p);
    m_spec = base + "dbname=" + m_name;
}

TestDatabase::~TestDatabase() {
    if (!m_name.empty()) run(m_admin, "DROP DATABASE IF EXISTS " + m_name + " WITH (FORCE)");
}
#else
TestDatabase::TestDatabase(const std::string& scratch) : m_spec(scratch + "/results.sqlite") {}
TestDatabase::~TestDatabase() = default;
#endif

} // namespace viscera::test
