// Writes the seeds that are not taken from the exported samples into <dir>:
//   console_protocol/  a state, command, hello and welcome packet as the console and the player
//                      send them (two arms, pedals), signed with the harness's fixed key
//                      (fuzz_link_key.hpp), each once as received (mode byte 0) and once to be
//                      re-signed (mode byte 1), so that the fuzzer starts past the header and MAC;
//   link_auth/         a key, the right tag, a flip byte and a message (a state packet's body);
//   mesh_format/       a unit cube in each format the studio imports (OBJ with texture coordinates,
//                      normals and a material library, ASCII and binary STL, ASCII and binary PLY,
//                      GLB, glTF, ASCII FBX), each prefixed with the byte fuzz_mesh_format reads as
//                      the extension;
//   scene_blocks/      the assessment, laparoscope and port blocks of every <dir>/scene/*.json
//                      (the exported samples' scene.json, when fuzz.sh has put them there) and one
//                      of each written here, each prefixed with the byte fuzz_scene_blocks reads as
//                      the block (0 assessment, 1 laparoscope, 2 port);
//   session_report/    a judged session report with a trainee record (schema 5) whose metrics have
//                      limits and expert levels, beside the player's own reports that fuzz.sh adds.
#include "fuzz_link_key.hpp"
#include "haptics/console_protocol.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr std::array<std::array<float, 3>, 8> kCorners{{
    {0, 0, 0},
    {1, 0, 0},
    {1, 1, 0},
    {0, 1, 0},
    {0, 0, 1},
    {1, 0, 1},
    {1, 1, 1},
    {0, 1, 1},
}};
// Outward-facing triangles of the cube (counter-clockwise seen from outside).
constexpr std::array<std::array<int, 3>, 12> kTriangles{{
    {0, 2, 1},
    {0, 3, 2},
    {4, 5, 6},
    {4, 6, 7},
    {0, 1, 5},
    {0, 5, 4},
    {1, 2, 6},
    {1, 6, 5},
    {2, 3, 7},
    {2, 7, 6},
    {3, 0, 4},
    {3, 4, 7},
}};

void put32(std::string& s, uint32_t v) {
    for (int i = 0; i < 4; ++i)
        s += static_cast<char>((v >> (8 * i)) & 0xff);
}

void putF(std::string& s, float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    put32(s, v);
}

bool write(const std::filesystem::path& file, char prefix, const std::string& bytes) {
    std::ofstream out(file, std::ios::binary);
    out.put(prefix);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return static_cast<bool>(out);
}

std::string obj() {
    std::string s = "# cube\nmtllib cube.mtl\no cube\n";
    for (const auto& c : kCorners)
        s += "v " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(c[2]) + "\n";
    s += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 -1\nvn 0 0 1\nusemtl skin\ng sides\ns 1\n";
    for (size_t t = 0; t < kTriangles.size(); ++t) {
        s += "f";
        for (int k = 0; k < 3; ++k)
            s += " " + std::to_string(kTriangles[t][k] + 1) + "/" + std::to_string(k + 1) + "/" +
                 std::to_string(t % 2 + 1);
        s += "\n";
    }
    s += "f -8 -7 -6 -5\nl 1 2\n";
    return s;
}

std::string stlAscii() {
    std::string s = "solid cube\n";
    for (const auto& t : kTriangles) {
        s += "facet normal 0 0 0\n outer loop\n";
        for (int k : t)
            s += "  vertex " + std::to_string(kCorners[k][0]) + " " + std::to_string(kCorners[k][1]) + " " +
                 std::to_string(kCorners[k][2]) + "\n";
        s += " endloop\nendfacet\n";
    }
    return s + "endsolid cube\n";
}

std::string stlBinary() {
    std::string s(80, ' ');
    put32(s, kTriangles.size());
    for (const auto& t : kTriangles) {
        for (int i = 0; i < 3; ++i)
            putF(s, 0.0f);
        for (int k : t)
            for (float c : kCorners[k])
                putF(s, c);
        s += std::string(2, '\0');
    }
    return s;
}

std::string plyHeader(const char* format) {
    return std::string("ply\nformat ") + format + " 1.0\ncomment cube\nelement vertex 8\nproperty float x\n" +
           "property float y\nproperty float z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n";
}

std::string plyAscii() {
    std::string s = plyHeader("ascii");
    for (const auto& c : kCorners)
        s += std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(c[2]) + "\n";
    for (const auto& t : kTriangles)
        s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    return s;
}

std::string plyBinary() {
    std::string s = plyHeader("binary_little_endian");
    for (const auto& c : kCorners)
        for (float x : c)
            putF(s, x);
    for (const auto& t : kTriangles) {
        s += '\3';
        for (int k : t)
            put32(s, static_cast<uint32_t>(k));
    }
    return s;
}

std::string gltfJson(bool embedded) {
    const std::string buffer = embedded ? R"({"byteLength":240})" : R"({"byteLength":240,"uri":"cube.bin"})";
    return std::string(R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)") +
           R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)" +
           R"("accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},)" +
           R"({"bufferView":1,"componentType":5125,"count":36,"type":"SCALAR"}],)" +
           R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},{"buffer":0,"byteOffset":96,"byteLength":144}],)" +
           R"("buffers":[)" + buffer + "]}";
}

std::string gltfBuffer() {
    std::string s;
    for (const auto& c : kCorners)
        for (float x : c)
            putF(s, x);
    for (const auto& t : kTriangles)
        for (int k : t)
            put32(s, static_cast<uint32_t>(k));
    return s;
}

std::string glb() {
    std::string json = gltfJson(true);
    while (json.size() % 4)
        json += ' ';
    const std::string bin = gltfBuffer();
    std::string s = "glTF";
    put32(s, 2);
    put32(s, static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
    put32(s, static_cast<uint32_t>(json.size()));
    s += "JSON" + json;
    put32(s, static_cast<uint32_t>(bin.size()));
    s += std::string("BIN") + '\0' + bin;
    return s;
}

std::string fbxAscii() {
    return "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXVersion: 7400\n}\nObjects:  {\n"
           "\tGeometry: 1, \"Geometry::cube\", \"Mesh\" {\n\t\tVertices: *9 {\n\t\t\ta: 0,0,0,1,0,0,0,1,0\n\t\t}\n"
           "\t\tPolygonVertexIndex: *3 {\n\t\t\ta: 0,1,-3\n\t\t}\n\t}\n}\n";
}

/// Writes `bytes` with the mode byte `prefix` in front.
bool writeBytes(const std::filesystem::path& file, char prefix, const uint8_t* bytes, size_t n) {
    return write(file, prefix, std::string(reinterpret_cast<const char*>(bytes), n));
}

bool consoleSeeds(const std::filesystem::path& dir, const std::filesystem::path& linkDir) {
    using namespace viscera::haptics;
    const LinkMac mac(viscera::fuzz::kFuzzLinkKey);
    uint8_t buf[kMaxPacketSize];
    StatePacket s;
    s.sequence = 7;
    s.timestamp_ns = 123456789;
    s.arms = 2;
    s.pedals = 0x5;
    CommandPacket c;
    c.sequence = 9;
    c.echoSequence = 7;
    HelloPacket h;
    h.sequence = 1;
    h.client = Nonce{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
    WelcomePacket w;
    w.sequence = 1;
    w.client = h.client;
    w.server = Nonce{16, 15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1};
    bool ok = true;
    auto both = [&](const char* name, size_t n) {
        ok = ok && n > 0 && writeBytes(dir / (std::string(name) + ".bin"), 0, buf, n) &&
             writeBytes(dir / (std::string(name) + "-resign.bin"), 1, buf, n);
    };
    both("state", encode(s, buf, sizeof buf, mac));
    both("command", encode(c, buf, sizeof buf, mac));
    both("hello", encode(h, buf, sizeof buf, mac));
    both("welcome", encode(w, buf, sizeof buf, mac));
    // link_auth: key, tag, flip byte, message (the state packet's signed part).
    const size_t n = encode(s, buf, sizeof buf, mac);
    std::string seed(viscera::fuzz::kFuzzLinkKey.begin(), viscera::fuzz::kFuzzLinkKey.end());
    seed.append(reinterpret_cast<const char*>(buf + n - kLinkTagSize), kLinkTagSize);
    seed += '\x2a';
    seed.append(reinterpret_cast<const char*>(buf), n - kLinkTagSize);
    std::ofstream(linkDir / "state.bin", std::ios::binary) << seed;
    return ok && n > 0;
}

/// The blocks fuzz_scene_blocks reads, from a scene.json: its assessment, its laparoscope, and the
/// port of every tool and instrument.
void sceneBlockSeeds(const std::filesystem::path& sceneDir, const std::filesystem::path& out) {
    if (!std::filesystem::is_directory(sceneDir)) return;
    for (const auto& entry : std::filesystem::directory_iterator(sceneDir)) {
        std::ifstream in(entry.path(), std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        const nlohmann::json doc = nlohmann::json::parse(text.str(), nullptr, false);
        if (!doc.is_object()) continue;
        const std::string stem = entry.path().stem().string();
        if (doc.contains("assessment")) write(out / (stem + "-assessment.json"), 0, doc["assessment"].dump(1));
        if (doc.contains("laparoscope")) write(out / (stem + "-laparoscope.json"), 1, doc["laparoscope"].dump(1));
        int k = 0;
        auto ports = [&](const nlohmann::json& list) {
            if (!list.is_array()) return;
            for (const auto& t : list)
                if (t.is_object() && t.contains("port"))
                    write(out / (stem + "-port" + std::to_string(k++) + ".json"), 2, t["port"].dump(1));
        };
        if (doc.contains("tools")) ports(doc["tools"]);
        if (doc.contains("interaction") && doc["interaction"].is_object() && doc["interaction"].contains("instruments"))
            ports(doc["interaction"]["instruments"]);
    }
}

bool builtInBlocks(const std::filesystem::path& out) {
    const std::string assessment = R"({"targets": {
  "cut": [{"line": [[0, 0, 0.02], [0.03, 0, 0.02]], "radius": 0.005, "coverage": 0.6}],
  "clip": [{"position": [0.01, 0.01, 0.02], "tolerance": 0.008, "count": 2}],
  "suture": {"plane": {"point": [0, 0, 0], "normal": [1, 0, 0]}, "bites": 2, "depth": [0.001, 0.006],
             "spacing": [0.001, 0.01], "max_gap": 0.0005},
  "vessel": {"body": "vessel", "margin": 0.0015}},
 "force_threshold_n": 1.0, "reference_path_m": 0.25,
 "metrics": {"completion_time_s": {"limit": 120, "expert": {"mean": 60, "sd": 10}},
             "path_length_m": {"limit": 2.5}, "out_of_view_s": {"expert": {"mean": 1, "sd": 0.5}},
             "instrument_collisions": {"limit": 3}, "economy_of_motion": {"limit": 4},
             "vessel_injury_s": {"limit": 0.1}, "cut_coverage": {"limit": 0.6},
             "clips_on_target": {"limit": 2}}})";
    const std::string laparoscope = R"({"port": {"position": [0, -0.15, 0.09], "insertion": [0.02, 0.3],
 "max_angle_deg": 60, "shaft_length": 0.36}, "tip": [-0.01, -0.045, 0.055], "optic_deg": 30, "fov_deg": 70,
 "hand": "right", "motion_scale": 0.3})";
    const std::string port = R"({"position": [0, 0, 0.15], "insertion": [0.02, 0.3], "max_angle_deg": 60,
 "shaft_length": 0.36, "mode": "robotic"})";
    return write(out / "builtin-assessment.json", 0, assessment) &&
           write(out / "builtin-laparoscope.json", 1, laparoscope) && write(out / "builtin-port.json", 2, port);
}

/// A judged report as the player writes it (schema 5): the record, the assessment with a metric of
/// each kind (limit, expert level, no value), and a few of the other sections.
std::string judgedReport() {
    return R"({
  "schemaVersion": 5,
  "case": {"id": "rectum", "version": "1.0.0", "title": "Rectum"},
  "record": {"trainee": "trainee.01@example", "started_utc": "2026-12-05T19:50:00Z", "player_version": "0.1.0",
             "case_id": "rectum", "case_version": "1.0.0",
             "package_sha256": "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef"},
  "assessment": {"judged": true, "passed": false, "completion_time_s": 12.5, "within_expert_level": false,
    "metrics": [
      {"name": "completion_time_s", "unit": "s", "value": 12.5, "better": "lower", "limit": 20, "passed": true,
       "expert": {"mean": 6, "sd": 1, "bound": 8}, "within_expert": false},
      {"name": "cut_coverage", "unit": "1", "value": 0.8, "better": "higher", "limit": 0.6, "passed": true,
       "expert": {"mean": 0.9, "sd": 0.05, "bound": 0.8}, "within_expert": true},
      {"name": "vessel_injury_s", "unit": "s", "value": 0.65, "better": "lower", "limit": 0.1, "passed": false,
       "expert": null, "within_expert": null},
      {"name": "out_of_view_s", "unit": "s", "value": null, "better": "lower", "limit": null, "passed": true,
       "expert": {"mean": 1, "sd": 0.5, "bound": 2}, "within_expert": false}],
    "tools": [{"name": "hook", "kind": "hook", "hand": "right", "path_m": 0.4, "angular_path_rad": 1.2,
               "force_max_n": 2.1, "force_mean_n": 0.4, "force_over_threshold_s": 0.3, "tissue_damage_ns": 0.02}]},
  "frames": [{"index": 0, "step_ms": 1.5, "substeps": 10, "iterations": 1, "energy_j": 0.001,
              "max_displacement_m": 0.0001}],
  "metrics": {"frames": 1, "sim_time_s": 0.0166}
}
)";
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: make_seeds <dir>\n");
        return 2;
    }
    const std::filesystem::path root = argv[1];
    const std::filesystem::path console = root / "console_protocol";
    const std::filesystem::path link = root / "link_auth";
    const std::filesystem::path mesh = root / "mesh_format";
    const std::filesystem::path blocks = root / "scene_blocks";
    const std::filesystem::path report = root / "session_report";
    for (const auto& d : {console, link, mesh, blocks, report})
        std::filesystem::create_directories(d);
    bool ok = consoleSeeds(console, link);
    // The prefix byte is the index in fuzz_mesh_format's list: .obj .stl .ply .glb .gltf .fbx
    ok = ok && write(mesh / "cube.obj", 0, obj()) && write(mesh / "cube-ascii.stl", 1, stlAscii()) &&
         write(mesh / "cube-binary.stl", 1, stlBinary()) && write(mesh / "cube-ascii.ply", 2, plyAscii()) &&
         write(mesh / "cube-binary.ply", 2, plyBinary()) && write(mesh / "cube.glb", 3, glb()) &&
         write(mesh / "cube.gltf", 4, gltfJson(false)) && write(mesh / "cube.fbx", 5, fbxAscii());
    sceneBlockSeeds(root / "scene", blocks);
    ok = ok && builtInBlocks(blocks);
    ok = ok && static_cast<bool>(std::ofstream(report / "judged.json", std::ios::binary) << judgedReport());
    std::printf("make_seeds: packets in %s and %s, 8 meshes in %s, blocks in %s, a report in %s\n", console.c_str(),
                link.c_str(), mesh.c_str(), blocks.c_str(), report.c_str());
    return ok ? 0 : 1;
}
