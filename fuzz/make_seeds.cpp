// Writes the seeds that are not taken from the exported samples into <dir>:
//   console_protocol/  a state packet and a command packet as the console and the player send them
//                      (two arms, pedals), so that the fuzzer starts past the header and checksum;
//   mesh_format/       a unit cube in each format the studio imports (OBJ with texture coordinates,
//                      normals and a material library, ASCII and binary STL, ASCII and binary PLY,
//                      GLB, glTF, ASCII FBX), each prefixed with the byte fuzz_mesh_format reads as
//                      the extension.
#include "haptics/console_protocol.hpp"

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

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

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: make_seeds <dir>\n");
        return 2;
    }
    const std::filesystem::path root = argv[1];
    const std::filesystem::path console = root / "console_protocol";
    const std::filesystem::path mesh = root / "mesh_format";
    std::filesystem::create_directories(console);
    std::filesystem::create_directories(mesh);
    uint8_t buf[2048];
    viscera::haptics::StatePacket s;
    s.sequence = 7;
    s.timestamp_ns = 123456789;
    s.arms = 2;
    s.pedals = 0x5;
    const size_t ns = viscera::haptics::encode(s, buf, sizeof buf);
    std::ofstream(console / "state.bin", std::ios::binary).write(reinterpret_cast<const char*>(buf), long(ns));
    viscera::haptics::CommandPacket c;
    c.sequence = 9;
    c.echoSequence = 7;
    const size_t nc = viscera::haptics::encode(c, buf, sizeof buf);
    std::ofstream(console / "command.bin", std::ios::binary).write(reinterpret_cast<const char*>(buf), long(nc));
    // The prefix byte is the index in fuzz_mesh_format's list: .obj .stl .ply .glb .gltf .fbx
    bool ok = write(mesh / "cube.obj", 0, obj()) && write(mesh / "cube-ascii.stl", 1, stlAscii()) &&
              write(mesh / "cube-binary.stl", 1, stlBinary()) && write(mesh / "cube-ascii.ply", 2, plyAscii()) &&
              write(mesh / "cube-binary.ply", 2, plyBinary()) && write(mesh / "cube.glb", 3, glb()) &&
              write(mesh / "cube.gltf", 4, gltfJson(false)) && write(mesh / "cube.fbx", 5, fbxAscii());
    std::printf("make_seeds: %zu + %zu bytes in %s, 8 meshes in %s\n", ns, nc, console.c_str(), mesh.c_str());
    return ns && nc && ok ? 0 : 1;
}
