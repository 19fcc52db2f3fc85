#pragma once
// The database a results test runs against: a SQLite file in the test's scratch folder, or (built
// with VISCERA_RESULTS_TEST_POSTGRES) a fresh database on the fixture's PostgreSQL server
// (tests/player/results/pg_server.sh), dropped at the end.
#include <string>

namespace viscera::test {

class TestDatabase {
public:
    /// `scratch`: the test's folder (the SQLite file goes there).
    explicit TestDatabase(const std::string& scratch);
    ~TestDatabase();
    TestDatabase(const TestDatabase&) = delete;
    TestDatabase& operator=(const TestDatabase&) = delete;
    /// The --db argument.
    const std::string& spec() const { return m_spec; }
    /// "" or the reason the database could not be made (the test fails with it).
    const std::string& error() const { return m_error; }

private:
    std::string m_spec, m_error, m_admin, m_name;
};

} // namespace viscera::test
