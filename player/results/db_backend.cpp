// The backend choice: the one place that knows whether PostgreSQL support was built.
#include "results/db_backend.hpp"

#include "sim/util/error.hpp"

namespace viscera::player::detail {

bool isPostgresSpec(const std::string& spec) {
    return spec.rfind("postgresql:", 0) == 0 || spec.rfind("postgres:", 0) == 0 ||
           spec.find("host=") != std::string::npos || spec.find("dbname=") != std::string::npos;
}

std::unique_ptr<DbBackend> openBackend(const std::string& spec, bool mustExist) {
    if (spec.empty()) throw InputError("--db: must not be empty");
    if (!isPostgresSpec(spec)) return openSqlite(spec, mustExist);
#ifdef VISCERA_WITH_POSTGRES
    return openPostgres(spec);
#else
    throw InputError("--db: PostgreSQL databases need a viscera-results built with VISCERA_WITH_POSTGRES (libpq)");
#endif
}

} // namespace viscera::player::detail
