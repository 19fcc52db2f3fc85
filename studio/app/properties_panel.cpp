#include "app/properties_panel.hpp"

#include "app/hold_tool.hpp"
#include "app/material_panel.hpp"
#include "app/number_text.hpp"
#include "sim/material/material.hpp"

#include <QComboBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QRegularExpression>
#include <QTimer>
#include <QToolButton>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

namespace viscera::studio {
namespace {

const char* const kBodyFields[] = {"youngs_modulus", "poisson_ratio", "density"};
const char* const kSolverFields[] = {"dt", "substeps", "iterations", "damping"};
const char* const kPlacementFields[] = {"unit", "scale", "rotation_deg"};
const char* const kHoldMargin = "hold_margin_mm";
/// A meshed body's CGAL sizes, typed in millimetres (project.json meshing.facet_size, cell_size).
const char* const kMeshingFields[] = {"facet_size_mm", "cell_size_mm"};
/// A tissue layer's fields (project.json surfaces[i]).
const char* const kSurfaceFields[] = {"stretch_stiffness", "areal_density", "subdivide", "region_min", "region_max"};

/// Three numbers "x y z" (spaces or commas) into `out`; else the reason in `why`, `count` when
/// there are not three.
bool parseThreeNumbers(const QString& text, const QString& field, const QString& count, sim::Vec3& out, QString& why) {
    const QStringList parts = text.split(QRegularExpression("[\\s,]+"), Qt::SkipEmptyParts);
    if (parts.size() != 3) {
        why = count;
        return false;
    }
    for (int k = 0; k < 3; ++k) {
        const std::optional<double> v = parseNumberText(parts[k], field, why);
        if (!v) return false;
        out[k] = *v;
    }
    return true;
}

QString vec3Text(const sim::Vec3& v) {
    return QStringLiteral("%1 %2 %3").arg(numberText(v.x()), numberText(v.y()), numberText(v.z()));
}

/// A body whose tets CGAL makes from its remeshed anatomy: its sizes are typed.
bool meshedFromSurface(const Project& p, int body) {
    return body >= 0 && body < static_cast<int>(p.bodies.size()) &&
           p.bodies[static_cast<size_t>(body)].mesh.kind == MeshSource::Kind::Remesh;
}

bool madeFromAnatomy(const Project& p, int body) {
    return body >= 0 && body < static_cast<int>(p.bodies.size()) &&
           p.bodies[static_cast<size_t>(body)].mesh.kind == MeshSource::Kind::Remesh;
}

/// The text field `name` shows for the project (empty: not a field of this selection).
QString valueText(const Project& p, int body, int surface, const QString& name, const HoldTool* hold) {
    if (name == kHoldMargin && hold) return numberText(hold->margin() * 1000);
    if (surface >= 0 && surface < static_cast<int>(p.surfaces.size())) {
        const SurfaceProject& s = p.surfaces[static_cast<size_t>(surface)];
        if (name == "stretch_stiffness") return numberText(s.scene.stretchStiffness);
        if (name == "areal_density") return numberText(s.scene.arealDensity);
        if (name == "subdivide") return QString::number(s.subdivide);
        if (name == "region_min" && s.region) return vec3Text((*s.region)[0]);
        if (name == "region_max" && s.region) return vec3Text((*s.region)[1]);
        return {};
    }
    if (meshedFromSurface(p, body)) {
        const auto& m = p.bodies[static_cast<size_t>(body)].mesh.meshing;
        if (name == "facet_size_mm") return numberText(m.facetSize * 1000);
        if (name == "cell_size_mm") return numberText(m.cellSize * 1000);
    }
    if (body >= 0 && body < static_cast<int>(p.bodies.size())) {
        const sim::Material& m = p.bodies[body].scene.material;
        if (name == "youngs_modulus") return numberText(m.youngsModulus);
        if (name == "poisson_ratio") return numberText(m.poissonRatio);
        if (name == "density") return numberText(m.density);
    }
    if (madeFromAnatomy(p, body)) {
        const bake::ImportPlacement& q = p.bodies[static_cast<size_t>(body)].mesh.remesh.placement;
        if (name == "scale") return numberText(q.scale);
        if (name == "rotation_deg")
            return QStringLiteral("%1 %2 %3")
                .arg(numberText(q.rotationDeg.x()), numberText(q.rotationDeg.y()), numberText(q.rotationDeg.z()));
    }
    const auto& x = p.scene.xpbd;
    if (name == "dt") return numberText(x.dt);
    if (name == "substeps") return QString::number(x.substeps);
    if (name == "iterations") return QString::number(x.iterations);
    if (name == "damping") return numberText(x.damping);
    return {};
}

} // namespace

PropertiesPanel::PropertiesPanel(Document* doc, Selection* selection, MaterialPanel* material, QWidget* parent)
    : QWidget(parent), m_doc(doc), m_sel(selection), m_material(material) {
    setObjectName("propertiesPanel");
    auto* root = new QVBoxLayout(this);
    m_form = new QFormLayout;
    root->addLayout(m_form);
    m_error = new QLabel(this);
    m_error->setObjectName("propertyError");
    m_error->setWordWrap(true);
    m_error->setStyleSheet("color: #b00020");
    root->addWidget(m_error);
    root->addStretch();
    connect(m_sel, &Selection::changed, this, [this] {
        m_error->clear(); // a rule broken on another selection no longer applies
        scheduleRebuild();
    });
    connect(m_doc, &Document::changed, this, [this](const Change& what) {
        if (what.touches(Change::Structure))
            scheduleRebuild();
        else if (what.touches(Change::Material | Change::Solver))
            fillValues(false);
    });
}

void PropertiesPanel::scheduleRebuild() {
    if (m_pending) return;
    m_pending = true;
    QTimer::singleShot(0, this, [this] {
        m_pending = false;
        rebuild();
    });
}

void PropertiesPanel::addField(const QString& name, const QString& label) {
    auto* e = new QLineEdit(this);
    e->setObjectName(name);
    connect(e, &QLineEdit::editingFinished, this, [this, e, name] {
        if (e->isModified()) {
            e->setModified(false);
            setProperty(name, e->text());
        }
    });
    m_form->addRow(label, e);
}

void PropertiesPanel::addPlacementFields(const bake::ImportPlacement& placement) {
    auto* unit = new QComboBox(this);
    unit->setObjectName("unit");
    for (auto u :
         {bake::LengthUnit::Metre, bake::LengthUnit::Centimetre, bake::LengthUnit::Millimetre, bake::LengthUnit::Inch})
        unit->addItem(QString::fromUtf8(bake::unitName(u).data()));
    unit->setCurrentText(QString::fromUtf8(bake::unitName(placement.unit).data()));
    connect(unit, &QComboBox::currentTextChanged, this, [this](const QString& t) { setProperty("unit", t); });
    m_form->addRow(tr("Length unit of the parts"), unit);
    addField("scale", tr("Uniform scale"));
    addField("rotation_deg", tr("Rotation x y z [°]"));
}

void PropertiesPanel::addHoldRows(int body) {
    const size_t n = m_doc->project().bodies[static_cast<size_t>(body)].fixedBoxes.size();
    auto* count = new QLabel(n == 0 ? tr("nowhere (it falls under gravity)") : tr("in %n place(s)", "", int(n)), this);
    count->setObjectName("heldCount");
    m_form->addRow(tr("Held"), count);
    auto* tool = new QToolButton(this);
    tool->setObjectName("holdTissueButton");
    tool->setDefaultAction(m_hold->action());
    auto* release = new QPushButton(tr("Release holds"), this);
    release->setObjectName("releaseHoldsButton");
    release->setEnabled(n > 0);
    connect(release, &QPushButton::clicked, this, [this, body] {
        const QString why = m_hold->release(body);
        m_error->setText(why);
        if (!why.isEmpty()) emit logMessage(why);
    });
    auto* row = new QHBoxLayout;
    row->addWidget(tool);
    row->addWidget(release);
    m_form->addRow(QString(), row);
    addField(kHoldMargin, tr("Hold margin [mm]"));
}

void PropertiesPanel::rebuild() {
    ++m_builds;
    while (m_form->rowCount() > 0)
        m_form->removeRow(0);
    if (!m_doc->hasProject()) return;
    const Project& p = m_doc->project();
    const int body = m_sel->body(), surface = m_sel->surface();
    if (body >= 0 && body < static_cast<int>(p.bodies.size())) {
        const sim::Material& m = p.bodies[body].scene.material;
        m_form->addRow(tr("Body"), new QLabel(QString::fromStdString(p.bodies[body].scene.name), this));
        auto* model = new QComboBox(this);
        model->setObjectName("model");
        for (auto mm :
             {sim::MaterialModel::StableNeoHookean, sim::MaterialModel::NeoHookean, sim::MaterialModel::Linear,
              sim::MaterialModel::StVenantKirchhoff, sim::MaterialModel::Corotated, sim::MaterialModel::ValanisLandel})
            model->addItem(QString::fromStdString(sim::materialModelName(mm)));
        model->setCurrentText(QString::fromStdString(sim::materialModelName(m.model)));
        connect(model, &QComboBox::currentTextChanged, this, [this](const QString& t) { setProperty("model", t); });
        m_form->addRow(tr("Material model"), model);
        addField("youngs_modulus", tr("Young's modulus E [Pa]"));
        addField("poisson_ratio", tr("Poisson ratio ν"));
        addField("density", tr("Density [kg/m³]"));
        if (madeFromAnatomy(p, body)) addPlacementFields(p.bodies[static_cast<size_t>(body)].mesh.remesh.placement);
        if (meshedFromSurface(p, body)) {
            addField("facet_size_mm", tr("Surface triangle size [mm]"));
            addField("cell_size_mm", tr("Tet size [mm]"));
        }
        if (m_hold) addHoldRows(body);
    } else if (m_sel->kind() == Selection::Kind::Solver && p.scene.solverType == "xpbd") {
        addField("dt", tr("Frame step dt [s]"));
        addField("substeps", tr("Substeps per frame"));
        addField("iterations", tr("Iterations per substep"));
        addField("damping", tr("Damping [1/s]"));
    } else if (m_sel->kind() == Selection::Kind::Render) {
        auto* l =
            new QLabel(p.scene.render.empty() ? tr("renderer defaults") : QString::fromStdString(p.scene.render), this);
        l->setWordWrap(true);
        m_form->addRow(tr("Render"), l);
    } else if (surface >= 0 && surface < static_cast<int>(p.surfaces.size())) {
        const auto& s = p.surfaces[surface].scene;
        m_form->addRow(tr("Surface"), new QLabel(QString::fromStdString(s.name), this));
        addField("stretch_stiffness", tr("Stretch stiffness"));
        addField("areal_density", tr("Areal density [kg/m²]"));
        addField("subdivide", tr("Subdivisions (each halves its edges)"));
        addField("region_min", tr("Region min x y z [m] (empty: all)"));
        addField("region_max", tr("Region max x y z [m] (empty: all)"));
    }
    fillValues(true);
}

void PropertiesPanel::fillValues(bool force) {
    if (!m_doc->hasProject()) return;
    const Project& p = m_doc->project();
    for (QLineEdit* e : findChildren<QLineEdit*>()) {
        const QString v = valueText(p, m_sel->body(), m_sel->surface(), e->objectName(), m_hold);
        if (v.isEmpty() || e->text() == v || (!force && e->isModified())) continue;
        e->setText(v);
        e->setModified(false);
    }
    if (auto* model = findChild<QComboBox*>("model");
        model && m_sel->body() >= 0 && m_sel->body() < static_cast<int>(p.bodies.size())) {
        const QString name =
            QString::fromStdString(sim::materialModelName(p.bodies[m_sel->body()].scene.material.model));
        if (model->currentText() != name) {
            const QSignalBlocker quiet(model);
            model->setCurrentText(name);
        }
    }
}

QString PropertiesPanel::setProperty(const QString& field, const QString& text) {
    QString why;
    const bool material =
        field == "model" || std::find(std::begin(kBodyFields), std::end(kBodyFields), field) != std::end(kBodyFields);
    const bool solver = std::find(std::begin(kSolverFields), std::end(kSolverFields), field) != std::end(kSolverFields);
    const bool placement =
        std::find(std::begin(kPlacementFields), std::end(kPlacementFields), field) != std::end(kPlacementFields);
    const bool meshing =
        std::find(std::begin(kMeshingFields), std::end(kMeshingFields), field) != std::end(kMeshingFields);
    const bool surface =
        std::find(std::begin(kSurfaceFields), std::end(kSurfaceFields), field) != std::end(kSurfaceFields);
    if (surface) {
        why = setSurfaceValue(field, text);
    } else if (meshing) {
        const std::optional<double> v = parseNumberText(text, field, why);
        if (v) why = setMeshingValue(field, *v / 1000);
    } else if (field == kHoldMargin && m_hold) {
        const std::optional<double> v = parseNumberText(text, field, why);
        if (v) why = m_hold->setMargin(*v / 1000);
    } else if (placement) {
        why = setPlacementValue(field, text);
    } else if (material) {
        why = setMaterialValue(field, text);
    } else if (solver) {
        const std::optional<double> v = parseNumberText(text, field, why);
        if (v) why = setSolverValue(field, *v, text);
    } else {
        why = tr("%1: not a property of the selection").arg(field);
    }
    m_error->setText(why);
    if (!why.isEmpty()) {
        emit logMessage(why);
        fillValues(true); // the field shows the model's value again
    }
    return why;
}

QString PropertiesPanel::setMaterialValue(const QString& field, const QString& text) {
    const int b = m_sel->body();
    if (!m_doc->hasProject() || b < 0 || b >= static_cast<int>(m_doc->project().bodies.size()))
        return tr("no body selected");
    sim::Material m = m_doc->project().bodies[b].scene.material;
    if (field == "model") {
        if (text == "valanis_landel") // editable curves of the neo-Hookean law at the body's E and ν
            return m.model == sim::MaterialModel::ValanisLandel
                       ? QString()
                       : m_material->applyPreset("neo_hookean", m.youngsModulus, m.poissonRatio);
        try {
            m.model = sim::materialModelFromName(text.toStdString());
        } catch (const std::exception& e) {
            return QString::fromStdString(e.what());
        }
        m.curvePreset.clear();
        m.fPrime.reset();
        m.gPrime.reset();
        m.hPrime.reset();
        return m_doc->editMaterial(tr("Set material model"), b, m);
    }
    QString why;
    const std::optional<double> v = parseNumberText(text, field, why);
    if (!v) return why;
    if (field == "youngs_modulus") m.youngsModulus = *v;
    if (field == "poisson_ratio") m.poissonRatio = *v;
    if (field == "density") m.density = *v;
    return m_doc->editMaterial(tr("Set %1").arg(field), b, m);
}

QString PropertiesPanel::setPlacementValue(const QString& field, const QString& text) {
    const int b = m_sel->body();
    if (!m_doc->hasProject() || !madeFromAnatomy(m_doc->project(), b)) return tr("no body made from anatomy selected");
    bake::ImportPlacement q = m_doc->project().bodies[static_cast<size_t>(b)].mesh.remesh.placement;
    QString why;
    if (field == "unit") {
        const auto unit = bake::lengthUnitFromName(text.toStdString());
        if (!unit) return tr("unit: '%1' is not a length unit (m, cm, mm, inch)").arg(text);
        q.unit = *unit;
    } else if (field == "scale") {
        const std::optional<double> v = parseNumberText(text, field, why);
        if (!v) return why;
        q.scale = *v;
    } else {
        sim::Vec3 angles;
        if (!parseThreeNumbers(text, field, tr("rotation_deg: '%1' must be three angles (x y z, degrees)").arg(text),
                               angles, why))
            return why;
        q.rotationDeg = angles;
    }
    return m_doc->editPlacement(tr("Set %1").arg(field), b, q);
}

QString PropertiesPanel::setMeshingValue(const QString& field, double metres) {
    const int b = m_sel->body();
    if (!m_doc->hasProject() || !meshedFromSurface(m_doc->project(), b)) return tr("no meshed body selected");
    return m_doc->edit(
        tr("Set %1").arg(field),
        [&](Project& p) {
            bake::MeshingParams& m = p.bodies[static_cast<size_t>(b)].mesh.meshing;
            (field == "cell_size_mm" ? m.cellSize : m.facetSize) = metres;
        },
        0, Change{Change::Structure});
}

QString PropertiesPanel::setSurfaceValue(const QString& field, const QString& text) {
    const int s = m_sel->surface();
    if (!m_doc->hasProject() || s < 0 || s >= static_cast<int>(m_doc->project().surfaces.size()))
        return tr("no tissue layer selected");
    QString why;
    if (field == "region_min" || field == "region_max") return setLayerRegion(s, field, text);
    const std::optional<double> v = parseNumberText(text, field, why);
    if (!v) return why;
    if (field == "subdivide" && *v != std::floor(*v)) // its range is the reader's rule, checked by edit()
        return tr("surfaces[%1].subdivide: '%2' must be a whole number").arg(s).arg(text);
    return m_doc->edit(
        tr("Set %1").arg(field),
        [&](Project& p) {
            SurfaceProject& layer = p.surfaces[static_cast<size_t>(s)];
            if (field == "stretch_stiffness") layer.scene.stretchStiffness = *v;
            if (field == "areal_density") layer.scene.arealDensity = *v;
            if (field == "subdivide") layer.subdivide = static_cast<int>(std::clamp(*v, -1e9, 1e9));
        },
        0, Change{Change::Structure});
}

QString PropertiesPanel::setLayerRegion(int s, const QString& field, const QString& text) {
    std::optional<std::array<sim::Vec3, 2>> region = m_doc->project().surfaces[static_cast<size_t>(s)].region;
    if (!text.trimmed().isEmpty()) {
        sim::Vec3 corner;
        QString why;
        if (!parseThreeNumbers(text, field,
                               tr("surfaces[%1].region: '%2' must be three numbers (x y z, m)").arg(s).arg(text),
                               corner, why))
            return why;
        if (!region) region = std::array<sim::Vec3, 2>{sim::Vec3::Constant(-1), sim::Vec3::Constant(1)};
        (*region)[field == "region_min" ? 0 : 1] = corner;
    } else {
        region.reset(); // the whole boundary
    }
    return m_doc->edit(
        tr("Set %1").arg(field), [&](Project& p) { p.surfaces[static_cast<size_t>(s)].region = region; }, 0,
        Change{Change::Structure});
}

QString PropertiesPanel::setSolverValue(const QString& field, double v, const QString& text) {
    if ((field == "substeps" || field == "iterations") && v != std::floor(v))
        return tr("solver.%1: '%2' must be a whole number").arg(field, text);
    // A whole number past any valid count still reaches the reader's rule, which names the range.
    const int count = static_cast<int>(std::clamp(v, -1e9, 1e9));
    if (!m_doc->hasProject()) return tr("no project is open");
    sim::XpbdSettings s = m_doc->project().scene.xpbd;
    if (field == "dt") s.dt = v;
    if (field == "substeps") s.substeps = count;
    if (field == "iterations") s.iterations = count;
    if (field == "damping") s.damping = v;
    return m_doc->editSolver(tr("Set solver %1").arg(field), s);
}

} // namespace viscera::studio
