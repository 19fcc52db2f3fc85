#include "project/anatomy_shapes.hpp"

#include "bake/import.hpp"
#include "project/project.hpp"

#include "sim/scene/scene_json.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace viscera::studio {

using nlohmann::json;
using sim::JsonField;
using sim::NumberRule;
using sim::Vec3;

namespace {

json vec3(const Vec3& v) {
    return {v.x(), v.y(), v.z()};
}

/// Two unit vectors across the unit axis `a`: u towards the scene's +z (else +y), v = a × u.
std::pair<Vec3, Vec3> across(const Vec3& a) {
    Vec3 u = Vec3::UnitZ() - Vec3::UnitZ().dot(a) * a;
    if (u.norm() < 1e-6) u = Vec3::UnitY() - Vec3::UnitY().dot(a) * a;
    u.normalize();
    return {u, a.cross(u)};
}

sim::TriMesh cylinder(const SceneryProject& s) {
    const Vec3 a = (s.end - s.start).normalized();
    const auto [u, v] = across(a);
    const bool whole = s.toDeg - s.fromDeg >= 360 - 1e-9;
    const int columns = whole ? s.slices : s.slices + 1; // a whole turn closes on its first column
    std::vector<Vec3> p;
    for (int r = 0; r <= s.rings; ++r) {
        const Vec3 c = s.start + (s.end - s.start) * (double(r) / s.rings);
        for (int k = 0; k < columns; ++k) {
            const double t = (s.fromDeg + (s.toDeg - s.fromDeg) * k / s.slices) * M_PI / 180.0;
            p.push_back(c + s.radius * (std::cos(t) * u + std::sin(t) * v));
        }
    }
    std::vector<sim::Tri> t;
    for (int r = 0; r < s.rings; ++r)
        for (int k = 0; k < s.slices; ++k) {
            const int a0 = r * columns + k, a1 = r * columns + (k + 1) % columns;
            const int b0 = a0 + columns, b1 = a1 + columns;
            if (s.inward) { // facing the axis: the surface is seen from inside
                t.push_back({a0, b0, b1});
                t.push_back({a0, b1, a1});
            } else {
                t.push_back({a0, b1, b0});
                t.push_back({a0, a1, b1});
            }
        }
    return sim::TriMesh::fromArrays(std::move(p), std::move(t), "scenery '" + s.name + "'");
}

sim::TriMesh disc(const SceneryProject& s) {
    const Vec3 n = s.normal.normalized();
    const auto [u, v] = across(n);
    std::vector<Vec3> p{s.center};
    for (int r = 1; r <= s.rings; ++r)
        for (int k = 0; k < s.slices; ++k) {
            const double t = 2 * M_PI * k / s.slices;
            p.push_back(s.center + s.radius * (double(r) / s.rings) * (std::cos(t) * u + std::sin(t) * v));
        }
    std::vector<sim::Tri> t;
    auto at = [&](int r, int k) { return 1 + (r - 1) * s.slices + (k % s.slices); };
    for (int k = 0; k < s.slices; ++k)
        t.push_back({0, at(1, k), at(1, k + 1)});
    for (int r = 1; r < s.rings; ++r)
        for (int k = 0; k < s.slices; ++k) {
            t.push_back({at(r, k), at(r + 1, k), at(r + 1, k + 1)});
            t.push_back({at(r, k), at(r + 1, k + 1), at(r, k + 1)});
        }
    return sim::TriMesh::fromArrays(std::move(p), std::move(t), "scenery '" + s.name + "'");
}

} // namespace

BendSpec readBend(const JsonField& bend) {
    bend.object({"radius", "center_y"});
    BendSpec b;
    b.radius = bend["radius"].number(NumberRule::closed(0.005, 1.0));
    b.centerY = bend.number("center_y", b.centerY, NumberRule::closed(-1.0, 1.0));
    return b;
}

json bendJson(const BendSpec& bend) {
    return {{"radius", bend.radius}, {"center_y", bend.centerY}};
}

Vec3 bendPoint(const BendSpec& bend, const Vec3& p) {
    const double theta = (p.y() - bend.centerY) / bend.radius, rho = bend.radius + p.z();
    return {p.x(), bend.centerY + rho * std::sin(theta), -bend.radius + rho * std::cos(theta)};
}

void bendPoints(const BendSpec& bend, std::vector<Vec3>& points) {
    for (size_t i = 0; i < points.size(); ++i) {
        if (!(bend.radius + points[i].z() > 0))
            throw std::invalid_argument("node " + std::to_string(i) + " lies " + std::to_string(-points[i].z()) +
                                        " m deep, at or below the bend's axis (radius " + std::to_string(bend.radius) +
                                        " m)");
        points[i] = bendPoint(bend, points[i]);
    }
}

std::vector<SceneryProject> readSceneryProject(const JsonField& scenery, std::set<std::string>& names,
                                               const std::filesystem::path& dir) {
    std::vector<SceneryProject> out;
    for (const JsonField& j : scenery.items(1, 16)) {
        SceneryProject s;
        const std::string gen = j["generator"].choice({"cylinder", "disc", "file"}, "a scenery generator");
        if (gen == "file") { // an imported surface, as it is
            j.object({"name", "generator", "file", "scale", "texture"});
            s.generator = SceneryProject::Generator::File;
            s.name = sim::readName(j["name"], names);
            s.file = projectFileOf(j["file"], dir);
            s.scale = j.number("scale", s.scale, NumberRule::aboveUpTo(0, 1000.0));
            out.push_back(std::move(s));
            continue;
        }
        s.generator = gen == "disc" ? SceneryProject::Generator::Disc : SceneryProject::Generator::Cylinder;
        if (s.generator == SceneryProject::Generator::Cylinder)
            j.object({"name", "generator", "start", "end", "radius", "from_deg", "to_deg", "facing", "slices", "rings",
                      "texture"});
        else
            j.object({"name", "generator", "center", "normal", "radius", "slices", "rings", "texture"});
        s.name = sim::readName(j["name"], names);
        s.radius = j["radius"].number(NumberRule::aboveUpTo(0, 1.0));
        s.slices = j.integer("slices", s.slices, 8, 256);
        s.rings = j.integer("rings", s.rings, 1, 256);
        if (s.generator == SceneryProject::Generator::Cylinder) {
            s.start = j["start"].vec3();
            s.end = j["end"].vec3();
            if (!((s.end - s.start).norm() > 1e-6)) j.failAt("end", "must differ from start");
            s.fromDeg = j.number("from_deg", s.fromDeg, NumberRule::closed(-360, 360));
            s.toDeg = j.number("to_deg", s.toDeg, NumberRule::closed(-360, 360));
            if (!(s.fromDeg < s.toDeg && s.toDeg <= s.fromDeg + 360))
                j.failAt("to_deg", "must lie above from_deg by at most 360");
            if (auto f = j.find("facing")) s.inward = f->choice({"inward", "outward"}, "a facing") == "inward";
        } else {
            s.center = j["center"].vec3();
            s.normal = j["normal"].vec3();
            if (!(s.normal.norm() > 1e-9)) j.failAt("normal", "must not be zero");
        }
        out.push_back(std::move(s));
    }
    return out;
}

json sceneryJson(const std::vector<SceneryProject>& scenery, const std::filesystem::path& dir) {
    json a = json::array();
    for (size_t k = 0; k < scenery.size(); ++k) {
        const SceneryProject& s = scenery[k];
        if (s.generator == SceneryProject::Generator::File) {
            a.push_back({{"name", s.name},
                         {"generator", "file"},
                         {"file", projectRelativePath(s.file, dir, "scenery[" + std::to_string(k) + "].file")},
                         {"scale", s.scale}});
            continue;
        }
        json j = {{"name", s.name}, {"radius", s.radius}, {"slices", s.slices}, {"rings", s.rings}};
        if (s.generator == SceneryProject::Generator::Cylinder) {
            j["generator"] = "cylinder";
            j["start"] = vec3(s.start);
            j["end"] = vec3(s.end);
            j["from_deg"] = s.fromDeg;
            j["to_deg"] = s.toDeg;
            j["facing"] = s.inward ? "inward" : "outward";
        } else {
            j["generator"] = "disc";
            j["center"] = vec3(s.center);
            j["normal"] = vec3(s.normal);
        }
        a.push_back(j);
    }
    return a;
}

sim::TriMesh scenerySurface(const SceneryProject& s) {
    if (s.generator == SceneryProject::Generator::File) {
        bake::ImportOptions o;
        o.scale = s.scale;
        return bake::importSurface(s.file, o);
    }
    return s.generator == SceneryProject::Generator::Disc ? disc(s) : cylinder(s);
}

} // namespace viscera::studio
