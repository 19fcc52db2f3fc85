// The scene's assessment, laparoscope and port blocks (sim/scene/assessment.*, the port and
// laparoscope readers of scene_json.hpp). The first byte picks the block (its value mod 3:
// assessment, laparoscope, a tool's port); the rest is the block's JSON text. Two ways in:
//   - the block reader itself (readAssessment, readLaparoscope, readPort) on the parsed text; a
//     block it accepts is written (writeAssessment, writeLaparoscope, writePort), and the written
//     block must be read again and written the same (numbers to 1e-12: a normal is normalized
//     again), as scene_json.hpp promises;
//   - the text as that block of a minimal valid scene.json (one body "vessel", two tools in the
//     left and right hand, the first through a port, and a laparoscope, so that every metric but
//     the suture's can be judged) through parseScene, where a scene it accepts must format and
//     parse again.
// A refusal (viscera::InputError) of the input is the expected outcome of bad input; a refusal of
// what the writer wrote aborts (a finding), as does anything else.
#include "sim/scene/scene.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace {

using namespace viscera::sim;
using nlohmann::json;

enum class Block { Assessment, Laparoscope, Port };

// Default blocks of the minimal scene (the one under test replaces its own).
constexpr std::string_view kPort = R"({"position": [0, 0, 0.15]})";
constexpr std::string_view kLaparoscope = R"({"port": {"position": [0, -0.15, 0.09]}, "tip": [-0.01, -0.045, 0.055]})";

std::string minimalScene(Block block, std::string_view text) {
    const std::string_view port = block == Block::Port ? text : kPort;
    const std::string_view scope = block == Block::Laparoscope ? text : kLaparoscope;
    std::string s = R"({"solver": {"type": "xpbd", "dt": 0.01},
  "bodies": [{"name": "vessel", "mesh": "vessel.vtet",
              "material": {"model": "linear", "youngs_modulus": 1000, "poisson_ratio": 0.3, "density": 1000}}],
  "tools": [{"name": "grasper", "hand": "left", "start": [0, 0, 0.05], "port": )";
    s += port;
    s += R"(},
            {"name": "hook", "hand": "right", "start": [0.02, 0, 0.05]}],
  "laparoscope": )";
    s += scope;
    if (block == Block::Assessment) {
        s += R"(,
  "assessment": )";
        s += text;
    }
    return s + "\n}\n";
}

bool near(const json& a, const json& b) {
    if (a.is_number() && b.is_number()) {
        const double x = a.get<double>(), y = b.get<double>();
        return std::abs(x - y) <= 1e-12 * std::max({1.0, std::abs(x), std::abs(y)});
    }
    if (a.type() != b.type() || a.size() != b.size()) return false;
    if (a.is_object()) {
        for (auto it = a.begin(); it != a.end(); ++it)
            if (!b.contains(it.key()) || !near(it.value(), b[it.key()])) return false;
        return true;
    }
    if (a.is_array()) {
        for (size_t i = 0; i < a.size(); ++i)
            if (!near(a[i], b[i])) return false;
        return true;
    }
    return a == b;
}

/// Reads the block at doc[key] (the reader's JSON path is `key`) and writes it into a fresh
/// document under `key`.
json readAndWrite(Block block, const json& doc, const std::string& origin) {
    json out;
    switch (block) {
    case Block::Assessment:
        writeAssessment(readAssessment(JsonField(doc.at("assessment"), "assessment", origin)), out);
        break;
    case Block::Laparoscope:
        writeLaparoscope(readLaparoscope(JsonField(doc.at("laparoscope"), "laparoscope", origin)), out);
        break;
    case Block::Port: {
        PortDesc p;
        readPort(JsonField(doc.at("port"), "tools[0].port", origin), p);
        writePort(p, out["port"]);
        break;
    }
    }
    return out;
}

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_scene_blocks: %s: %s\n", what, detail.c_str());
    std::abort();
}

void blockReader(Block block, std::string_view text) {
    static const char* kKeys[] = {"assessment", "laparoscope", "port"};
    json written;
    try {
        const json doc = {{kKeys[int(block)], parseJsonText(text, "scene.json")}};
        written = readAndWrite(block, doc, "scene.json");
    } catch (const viscera::InputError&) {
        return;
    }
    json again;
    try {
        again = readAndWrite(block, written, "scene.json (written)");
    } catch (const viscera::InputError& e) {
        finding("the reader refuses what the writer wrote", e.what() + std::string("\n") + written.dump());
    }
    if (!near(written, again)) finding("written twice, the block differs", written.dump() + "\n" + again.dump());
}

void sceneReader(Block block, std::string_view text) {
    const std::string scene = minimalScene(block, text);
    SceneDesc desc;
    try {
        desc = parseScene(scene, "scene.json");
    } catch (const viscera::InputError&) {
        return;
    }
    const std::string formatted = formatScene(desc);
    try {
        (void)parseScene(formatted, "scene.json (formatted)");
    } catch (const viscera::InputError& e) {
        finding("parseScene refuses what formatScene wrote", e.what() + std::string("\n") + formatted);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    const Block block = static_cast<Block>(data[0] % 3);
    const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
    blockReader(block, text);
    sceneReader(block, text);
    return 0;
}
