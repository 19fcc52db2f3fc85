#include "sample_bodies.hpp"

#include "sim/mesh/tet_io.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace viscera::bench {

using namespace viscera::sim;

namespace {

double extentOf(const TetMesh& m) {
    double e = 0;
    for (const Vec3& p : m.positions())
        e = std::max(e, (p - m.positions()[0]).norm());
    return e;
}

} // namespace

SampleBody boxBody(std::string name, const BoxSpec& spec, double E, double nu, double density, bool fixBottom) {
    SampleBody b;
    b.name = std::move(name);
    b.mesh = makeBoxTetMesh(spec);
    b.material.model = MaterialModel::StableNeoHookean;
    b.material.youngsModulus = E;
    b.material.poissonRatio = nu;
    b.material.density = density;
    b.extent = extentOf(*b.mesh);
    for (int32_t v = 0; v < static_cast<int32_t>(b.mesh->vertexCount()); ++v) {
        const Vec3& p = b.mesh->positions()[v];
        if (fixBottom ? p.z() < spec.origin.z() + 1e-9 : p.x() < spec.origin.x() + 1e-9) b.fixed.push_back(v);
    }
    return b;
}

SampleBody vtetBody(const std::string& spec) {
    std::vector<std::string> f;
    std::stringstream ss(spec);
    for (std::string part; std::getline(ss, part, ':');)
        f.push_back(part);
    if (f.size() != 5) throw std::runtime_error("--vtet " + spec + ": expected name:E:nu:density:path");
    std::ifstream in(f[4]);
    if (!in) throw std::runtime_error("cannot read " + f[4]);
    std::stringstream text;
    text << in.rdbuf();
    SampleBody b;
    b.name = f[0];
    b.mesh = parseVtet(text.str(), f[4]);
    b.material.model = MaterialModel::StableNeoHookean;
    b.material.youngsModulus = std::stod(f[1]);
    b.material.poissonRatio = std::stod(f[2]);
    b.material.density = std::stod(f[3]);
    b.extent = extentOf(*b.mesh);
    std::vector<double> z;
    for (const Vec3& p : b.mesh->positions())
        z.push_back(p.z());
    std::vector<double> sorted = z;
    std::sort(sorted.begin(), sorted.end());
    for (size_t v = 0; v < z.size(); ++v)
        if (z[v] <= sorted[sorted.size() / 20]) b.fixed.push_back(static_cast<int32_t>(v));
    return b;
}

std::vector<SampleBody> sampleBoxBodies() {
    std::vector<SampleBody> out;
    out.push_back(boxBody("tissue-slab", {Vec3::Zero(), Vec3(0.08, 0.04, 0.03), {16, 8, 6}}, 30000, 0.45, 1050, false));
    out.push_back(boxBody("rectum-fat", {Vec3(-0.06, -0.05, -0.008), Vec3(0.12, 0.10, 0.008), {60, 50, 2}}, 3000, 0.45,
                          950, true));
    out.push_back(boxBody("block30k", {Vec3::Zero(), Vec3(0.25, 0.2, 0.1), {25, 20, 10}}, 20000, 0.45, 1050, false));
    return out;
}

} // namespace viscera::bench
