// Renaming and deleting a body, adding and removing a tissue layer over one, as edits of the one
// model [issue 57 items 4 and 7]: general edits (the
// command holds both models, so undo restores the model exactly) checked by the project reader's
// name rule (sim::readName) and then by the rules of load (check()).
#include "app/document.hpp"

#include "sim/scene/scene_json.hpp"
#include "sim/util/json_reader.hpp"

#include <nlohmann/json.hpp>

#include <set>
#include <string>
#include <vector>

namespace viscera::studio {
namespace {

std::string bodyField(int i) {
    return "bodies[" + std::to_string(i) + "]";
}

/// Calls `fn(field, ref)` for every place of the model that holds the body name `name`, but for
/// body `self`'s own fields: the project.json path of the field and the string that holds it.
/// The places are every field the reader checks against the bodies: another body's embedded_in,
/// a surface's from_boundary_of, a clip applier's target, a tissue layer, the assessment's vessel
/// and the suture's gauge.
template <class P, class Fn> void forEachReference(P& p, const std::string& name, int self, Fn fn) {
    auto visit = [&](const std::string& field, auto& ref) {
        if (ref == name) fn(field, ref);
    };
    for (size_t j = 0; j < p.bodies.size(); ++j)
        if (static_cast<int>(j) != self)
            visit(bodyField(static_cast<int>(j)) + ".embedded_in", p.bodies[j].scene.embeddedIn);
    for (size_t s = 0; s < p.surfaces.size(); ++s)
        visit("surfaces[" + std::to_string(s) + "].from_boundary_of", p.surfaces[s].scene.attachTo);
    if (auto& in = p.scene.interaction) {
        for (size_t k = 0; k < in->instruments.size(); ++k)
            visit("interaction.instruments[" + std::to_string(k) + "].target", in->instruments[k].target);
        for (size_t t = 0; t < in->tissues.size(); ++t)
            visit("interaction.tissues[" + std::to_string(t) + "].layer", in->tissues[t].layer);
    }
    if (auto& a = p.scene.assessment; a && a->vessel) visit("assessment.targets.vessel.body", a->vessel->body);
    if (auto& su = p.scene.suture)
        for (size_t k = 0; k < su->gauge.size(); ++k)
            visit("suture.gauge[" + std::to_string(k) + "]", su->gauge[k]);
}

/// The names body `self`'s must be new to (the reader's one set): the other bodies, the surfaces,
/// the tools and the scenery.
std::set<std::string> otherNames(const Project& p, int self) {
    std::set<std::string> names;
    for (size_t j = 0; j < p.bodies.size(); ++j)
        if (static_cast<int>(j) != self) names.insert(p.bodies[j].scene.name);
    for (const SurfaceProject& s : p.surfaces)
        names.insert(s.scene.name);
    for (const sim::ToolDesc& t : p.scene.tools)
        names.insert(t.name);
    for (const SceneryProject& s : p.scenery)
        names.insert(s.name);
    return names;
}

/// The refusal of deleting `field`'s `name` while the model names it: every naming field, or empty
/// when none does. `self` as in forEachReference (-1: a layer, no body of its own).
QString namedByRefusal(const Project& p, const std::string& field, const std::string& name, int self) {
    std::string refs;
    forEachReference(p, name, self,
                     [&](const std::string& at, const std::string&) { refs += (refs.empty() ? "" : ", ") + at; });
    if (refs.empty()) return {};
    return QString::fromStdString((p.dir / "project.json").string() + ": " + field + ".name: '" + name +
                                  "' is named by " + refs + " (change or delete that first)");
}

/// What renaming or deleting a body changes: its name in the tree and the meshes (Structure), and
/// the references in the scene's interaction and the assessment.
Change bodyChange() {
    return {Change::Structure | Change::Scene | Change::Assessment, -1};
}

/// A first tissue layer added to a scene whose hook or scissors cut only bodies: the layer enters
/// their tissues (the dissection takes one layer), and the body it covers, cut at the reader's
/// defaults, takes kCoveredBodyIgnitionC and kCoveredBodyConductivity so that the hook opens the
/// layer over it.
void cutLayerToo(Project& q) {
    if (!q.scene.interaction || q.scene.interaction->tissues.empty()) return;
    std::vector<sim::DissectionTissueDesc>& tissues = q.scene.interaction->tissues;
    const SurfaceProject& layer = q.surfaces.front();
    for (sim::DissectionTissueDesc& t : tissues)
        if (t.layer == layer.scene.attachTo && t.ignitionC == sim::DissectionTissueDesc{}.ignitionC &&
            t.conductivity == sim::DissectionTissueDesc{}.conductivity)
            coverByLayer(t);
    sim::DissectionTissueDesc t;
    t.layer = layer.scene.name;
    tissues.insert(tissues.begin(), t);
}

} // namespace

QString Document::renameBody(int body, const QString& name) {
    if (!m_project || body < 0 || body >= static_cast<int>(m_project->bodies.size())) return tr("no body selected");
    const Project& p = *m_project;
    const std::string origin = (p.dir / "project.json").string();
    const std::string from = p.bodies[static_cast<size_t>(body)].scene.name, to = name.toStdString();
    if (to == from) return {}; // nothing to change: no undo step
    try {                      // the reader's rule for a name (characters, length, unique)
        std::set<std::string> names = otherNames(p, body);
        sim::readName(sim::JsonField(nlohmann::json(to), bodyField(body) + ".name", origin), names);
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    return edit(
        tr("Rename body %1 to %2").arg(QString::fromStdString(from), name),
        [&](Project& q) {
            q.bodies[static_cast<size_t>(body)].scene.name = to;
            forEachReference(q, from, body, [&](const std::string&, std::string& ref) { ref = to; });
        },
        0, bodyChange());
}

QString Document::removeBody(int body) {
    if (!m_project || body < 0 || body >= static_cast<int>(m_project->bodies.size())) return tr("no body selected");
    const Project& p = *m_project;
    const std::string name = p.bodies[static_cast<size_t>(body)].scene.name;
    if (QString why = namedByRefusal(p, bodyField(body), name, body); !why.isEmpty()) return why;
    return edit(
        tr("Delete body %1").arg(QString::fromStdString(name)),
        [body](Project& q) { q.bodies.erase(q.bodies.begin() + body); }, 0, bodyChange());
}

QString Document::addLayer(int body) {
    if (!m_project || body < 0 || body >= static_cast<int>(m_project->bodies.size())) return tr("no body selected");
    const Project& p = *m_project;
    const std::set<std::string> names = otherNames(p, -1);
    std::string name = "fascia";
    for (int k = 2; names.count(name); ++k)
        name = "fascia_" + std::to_string(k);
    SurfaceProject layer;
    layer.scene.name = name;
    layer.scene.attachTo = p.bodies[static_cast<size_t>(body)].scene.name;
    return edit(
        tr("Add tissue layer %1 over %2")
            .arg(QString::fromStdString(name), QString::fromStdString(layer.scene.attachTo)),
        [&](Project& q) {
            q.surfaces.push_back(layer);
            if (q.surfaces.size() == 1) cutLayerToo(q);
        },
        0, bodyChange());
}

QString Document::removeLayer(int surface) {
    if (!m_project || surface < 0 || surface >= static_cast<int>(m_project->surfaces.size()))
        return tr("no tissue layer selected");
    const Project& p = *m_project;
    const std::string name = p.surfaces[static_cast<size_t>(surface)].scene.name;
    // names are unique across bodies and layers: only the interaction's tissues can name a layer,
    // and the layer leaves them with it (refused when it is the only tissue they have)
    Project without = p;
    if (auto& in = without.scene.interaction) {
        std::erase_if(in->tissues, [&](const sim::DissectionTissueDesc& t) { return t.layer == name; });
        if (in->tissues.empty()) without.scene.interaction = p.scene.interaction;
    }
    if (QString why = namedByRefusal(without, "surfaces[" + std::to_string(surface) + "]", name, -1); !why.isEmpty())
        return why;
    return edit(
        tr("Delete tissue layer %1").arg(QString::fromStdString(name)),
        [&](Project& q) {
            q.surfaces.erase(q.surfaces.begin() + surface);
            q.scene.interaction = without.scene.interaction;
        },
        0, bodyChange());
}

} // namespace viscera::studio
