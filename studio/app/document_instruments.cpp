// The scene's instruments as edits of the one model [issue 57]: a typed edit of one instrument
// (checked by the scene reader's rules for the interaction section), and adding or removing one
// (general edits checked by the rules of load, the track file written into the project folder).
#include "app/document.hpp"
#include "app/value_command.hpp"

#include "bake/import.hpp"
#include "sim/scene/port.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <optional>

namespace viscera::studio {
namespace {

namespace fs = std::filesystem;
using Kind = sim::InstrumentDesc::Kind;
using Box = std::array<sim::Vec3, 2>; ///< {min, max}, m

/// m: a new instrument's rest tip lies this far above the bodies' bounds; its port this far
/// above the tip and this far to its hand's side (0.108 m from the tip: inside the reader's
/// default insertion [0.02, 0.3]).
constexpr double kTipClearance = 0.02, kPortHeight = 0.10, kPortSide = 0.04;
/// Points per axis a bent body's box is sampled with (the bend curves its faces).
constexpr int kBendSamples = 9;

std::string instrumentField(int i) {
    return "interaction.instruments[" + std::to_string(i) + "]";
}

/// The reader's message without its origin ("project.json: interaction...": editValue names the file).
std::string withoutOrigin(const std::string& why, const std::string& origin) {
    return why.rfind(origin + ": ", 0) == 0 ? why.substr(origin.size() + 2) : why;
}

/// One instrument of the scene's interaction: the reader's rules on the section with it in place.
struct InstrumentSlot {
    using Value = sim::InstrumentDesc;
    static constexpr int kId = 571;
    static Value& of(Project& p, int i) { return p.scene.interaction->instruments.at(static_cast<size_t>(i)); }
    static Change change(int) { return {Change::Scene, -1}; }
    static std::string check(const Project& p, int i, const Value& v) {
        const std::string origin = "project.json";
        std::vector<std::string> bodies, surfaces;
        for (const BodyProject& b : p.bodies)
            bodies.push_back(b.scene.name);
        for (const SurfaceProject& s : p.surfaces)
            surfaces.push_back(s.scene.name);
        try { // the section as the writer writes it, read back; then its names and the assessment's
            sim::SceneDesc scene = p.scene;
            scene.interaction->instruments.at(static_cast<size_t>(i)) = v;
            const nlohmann::json section = sim::interactionJson(*scene.interaction);
            const sim::InteractionDesc back =
                sim::readInteractionSection(sim::JsonField(section, "interaction", origin));
            sim::checkInteractionNames(back, bodies, surfaces, origin);
            sim::checkAssessmentMeasurable(scene, bodies, origin);
        } catch (const std::exception& e) {
            return withoutOrigin(e.what(), origin);
        }
        const std::string where = instrumentField(i);
        sim::InstrumentTrack track;
        try { // the project reader's check of a track (readInteractionProject)
            track = sim::InstrumentTrack::parse(v.trackText, where + ".track");
        } catch (const std::exception& e) {
            return e.what();
        }
        if (v.port.declared && !track.keys().empty()) // World::assemble's rule (interaction_runtime.cpp)
            if (const std::string why = sim::restTipError(v.port, track.keys().front().position); !why.empty())
                return where + ".port: the track's first tip " + why;
        return {};
    }
};

void grow(std::optional<Box>& box, const sim::Vec3& q) {
    if (!box) box = Box{q, q};
    box->at(0) = box->at(0).cwiseMin(q);
    box->at(1) = box->at(1).cwiseMax(q);
}

/// The bounds of a body's source before the bend: from a generator's numbers, or the files'
/// surfaces as imported (none when a file cannot be read: the instrument is placed by the others).
std::optional<Box> sourceBounds(const MeshSource& m) {
    using K = MeshSource::Kind;
    std::optional<Box> box;
    const sim::Vec3 r = sim::Vec3::Constant(m.radius), ro = sim::Vec3::Constant(m.hollow.outerRadius);
    switch (m.kind) {
    case K::Box:
        grow(box, m.box.origin);
        grow(box, m.box.origin + m.box.size);
        break;
    case K::Ellipsoid:
    case K::Liver:
        grow(box, m.center - m.radii);
        grow(box, m.center + m.radii);
        break;
    case K::Tube:
        for (const sim::Vec3& e : {m.center, m.end}) {
            grow(box, e - r);
            grow(box, e + r);
        }
        break;
    case K::HollowTube:
        for (const sim::Vec3& e : {m.hollow.start, m.hollow.end}) {
            grow(box, e - ro);
            grow(box, e + ro);
        }
        break;
    case K::File:
    case K::Remesh:
        try {
            std::vector<std::pair<fs::path, bake::ImportOptions>> files;
            if (m.kind == K::File) {
                bake::ImportOptions o;
                o.scale = m.scale;
                files.emplace_back(m.file, o);
            } else {
                for (const RemeshSource::Part& part : m.remesh.parts)
                    files.emplace_back(part.file, bake::placedOptions(m.remesh.placement));
            }
            for (const auto& [file, options] : files) {
                const Box b = bake::importSurface(file, options).bounds();
                grow(box, b[0]);
                grow(box, b[1]);
            }
        } catch (const std::exception&) {
            return std::nullopt;
        }
        break;
    }
    return box;
}

/// The bounds of every body as the scene has them (the bend applied to a sampled box).
std::optional<Box> bodiesBounds(const Project& p) {
    std::optional<Box> all;
    for (const BodyProject& b : p.bodies) {
        const std::optional<Box> box = sourceBounds(b.mesh);
        if (!box) continue;
        if (!p.bend) {
            grow(all, box->at(0));
            grow(all, box->at(1));
            continue;
        }
        for (int i = 0; i < kBendSamples; ++i)
            for (int j = 0; j < kBendSamples; ++j)
                for (int k = 0; k < kBendSamples; ++k) {
                    const sim::Vec3 t = sim::Vec3(i, j, k) / (kBendSamples - 1);
                    grow(all, bendPoint(*p.bend, box->at(0) + t.cwiseProduct(box->at(1) - box->at(0))));
                }
    }
    return all;
}

/// The body a new clip applier clips: the one the others clip, else the first body.
std::string clipTarget(const Project& p) {
    if (p.scene.interaction)
        for (const sim::InstrumentDesc& in : p.scene.interaction->instruments)
            if (in.kind == Kind::ClipApplier) return in.target;
    return p.bodies.empty() ? std::string() : p.bodies.front().scene.name;
}

/// An instrument of `kind` on the master `hand` at rest above the bodies (no name yet): its port
/// with the reader's defaults above the tip, to the hand's side, and a one-key track there.
sim::InstrumentDesc restingInstrument(const Project& p, Kind kind, const std::string& hand) {
    sim::InstrumentDesc in;
    in.kind = kind;
    if (kind == Kind::ClipApplier) in.target = clipTarget(p);
    if (kind == Kind::Scissors) { // long slim blades
        in.jawLength = 0.014;
        in.radius = 0.0015;
    }
    if (kind == Kind::NeedleDriver) { // short strong jaws
        in.jawLength = 0.009;
        in.radius = 0.002;
    }
    in.device.declared = true;
    in.device.hand = hand;
    const Box box = bodiesBounds(p).value_or(Box{sim::Vec3::Zero(), sim::Vec3::Zero()});
    const sim::Vec3 g = p.scene.xpbd.gravity;
    const sim::Vec3 up = g.norm() > 0 ? sim::Vec3(-g.normalized()) : sim::Vec3::UnitZ();
    sim::Vec3 side = sim::Vec3::UnitX() - up * up.x();
    side = side.norm() > 1e-6 ? sim::Vec3(side.normalized()) : sim::Vec3::UnitY();
    const double sign = hand == "left" ? -1.0 : hand == "right" ? 1.0 : 0.0;
    const sim::Vec3 size = box[1] - box[0];
    const double halfHeight = 0.5 * up.cwiseAbs().dot(size);
    const sim::Vec3 tip = 0.5 * (box[0] + box[1]) + up * (halfHeight + kTipClearance);
    in.port.declared = true;
    in.port.position = tip + up * kPortHeight + side * (sign * kPortSide);
    sim::InstrumentKey key;
    key.position = tip;
    key.direction = (tip - in.port.position).normalized();
    key.jaw = 1;
    in.trackText = sim::InstrumentTrack({key}).format();
    return in;
}

/// The kind's name, new among the instruments, whose tools/<name>.track is free in the folder
/// (or holds `trackText` already: an earlier add of the same instrument).
std::string newInstrumentName(const Project& p, Kind kind, const std::string& trackText) {
    const std::string base = sim::kindName(kind);
    for (int n = 1; n < 1000; ++n) {
        const std::string name = n == 1 ? base : base + "_" + std::to_string(n);
        bool used = false;
        if (p.scene.interaction)
            for (const sim::InstrumentDesc& in : p.scene.interaction->instruments)
                used |= in.name == name;
        if (used) continue;
        const fs::path file = p.dir / "tools" / (name + ".track");
        std::error_code ec;
        if (!fs::exists(file, ec)) return name;
        try {
            if (readFile(file) == trackText) return name;
        } catch (const InputError&) { // unreadable: not ours to take
        }
    }
    throw InputError((p.dir / "tools").string() + ": no free track file name for a new " + base);
}

/// What an energy hook and the scissors cut when the scene names nothing: the first tissue layer
/// and the body it covers (kCoveredBodyIgnitionC and kCoveredBodyConductivity: the hook opens the
/// layer, the scissors divide both), else the first body, with the reader's defaults.
std::vector<sim::DissectionTissueDesc> defaultTissues(const Project& p) {
    std::vector<sim::DissectionTissueDesc> out(1);
    if (p.surfaces.empty()) {
        out[0].layer = p.bodies.front().scene.name;
        return out;
    }
    out[0].layer = p.surfaces.front().scene.name;
    for (const BodyProject& b : p.bodies)
        if (b.scene.name == p.surfaces.front().scene.attachTo) {
            sim::DissectionTissueDesc under;
            under.layer = b.scene.name;
            coverByLayer(under);
            out.push_back(under);
        }
    return out;
}

} // namespace

QString Document::editInstrument(const QString& text, int index, const sim::InstrumentDesc& value, int mergeKey) {
    if (!m_project || !m_project->scene.interaction || index < 0 ||
        index >= static_cast<int>(m_project->scene.interaction->instruments.size()))
        return tr("no instrument selected");
    sim::InstrumentDesc v = value;
    v.trackPath = "tools/" + v.name + ".track"; // the case path the project reader gives it
    return editValue<InstrumentSlot>(text, index, v, mergeKey);
}

QString Document::addInstrument(const QString& text, Kind kind, const std::string& hand) {
    if (!m_project) return tr("no project is open");
    if (m_project->bodies.empty()) return tr("an instrument needs a body to work on");
    sim::InstrumentDesc in;
    fs::path file;
    bool wrote = false;
    try {
        in = restingInstrument(*m_project, kind, hand);
        in.name = newInstrumentName(*m_project, kind, in.trackText);
        in.trackPath = "tools/" + in.name + ".track";
        file = m_project->dir / in.trackPath;
        if (!fs::exists(file)) { // the project's file enters its folder with the edit (load reads it)
            fs::create_directories(file.parent_path());
            writeFileAtomic(file, in.trackText);
            wrote = true;
        }
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    const QString why = edit(
        text,
        [&](Project& q) {
            if (!q.scene.interaction) {
                q.scene.interaction = sim::InteractionDesc{};
                // Tools on a body's own boundary: the polygon contact. On the soft bare body of the
                // cholecystectomy the circumsphere's spheres, sized by the deforming triangles,
                // threw nodes up to 60 mm a frame under a 34 mm/s press; the polygon contact moved
                // none farther than the settling did (10.6 mm, frame 3). The tools meet a body's
                // own boundary wherever a tissue layer leaves it bare (bare_body), so every new
                // interaction takes both (the rectum's hand-written circumsphere over its fascia
                // stays, its tools meeting the fascia alone).
                q.scene.interaction->collisionMethod = "polygon";
                q.scene.interaction->bareBody = true;
            }
            sim::InteractionDesc& d = *q.scene.interaction;
            if ((kind == Kind::EnergyHook || kind == Kind::Scissors) && d.tissues.empty())
                d.tissues = defaultTissues(q); // what they cut
            d.instruments.push_back(in);
            q.trackFiles.push_back(file);
        },
        0, Change{Change::Scene});
    if (!why.isEmpty() && wrote) {
        std::error_code ec;
        fs::remove(file, ec); // refused: the folder as it was
    }
    return why;
}

QString Document::removeInstrument(const QString& text, int index) {
    if (!m_project || !m_project->scene.interaction || index < 0 ||
        index >= static_cast<int>(m_project->scene.interaction->instruments.size()))
        return tr("no instrument selected");
    return edit(
        text,
        [index](Project& q) {
            std::vector<sim::InstrumentDesc>& list = q.scene.interaction->instruments;
            list.erase(list.begin() + index);
            q.trackFiles.erase(q.trackFiles.begin() + index);
            if (list.empty()) q.scene.interaction.reset(); // the reader needs at least one instrument
        },
        0, Change{Change::Scene});
}

} // namespace viscera::studio
