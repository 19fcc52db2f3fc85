// A session report as `viscera-results add` reads it (player/results/session_record.hpp,
// readSessionRecordFile without the file): the JSON text, then the trainee record and the
// assessment with every metric entry (runtime/assessment_json.hpp), then the report's sha256.
// player/ is not built here: its reader's sources are compiled into this harness (fuzz/CMakeLists.txt).
#include "results/session_record.hpp"
#include "runtime/report_reader.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const nlohmann::json doc = viscera::player::parseReportText(text, "report.json");
        viscera::player::SessionRecord s = viscera::player::readSessionRecord(doc, "report.json");
        s.reportSha256 = viscera::player::sha256Hex(text);
        if (s.reportSha256.size() != 64) std::abort();
    } catch (const viscera::InputError&) {
    }
    return 0;
}
