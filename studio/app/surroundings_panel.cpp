#include "app/surroundings_panel.hpp"

#include "app/anatomy_steps.hpp"
#include "app/document.hpp"
#include "app/number_text.hpp"
#include "bake/import.hpp"
#include "project/anatomy_shapes.hpp"

#include <QFileDialog>
#include <QFileInfo>
#include <QSettings>

#include <QComboBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QVBoxLayout>

#include <algorithm>

namespace viscera::studio {

namespace {

QString vecText(const sim::Vec3& v) {
    return QString("%1, %2, %3").arg(numberText(v.x()), numberText(v.y()), numberText(v.z()));
}

/// "x, y, z" (commas or spaces) as a vector, or nullopt with `why` naming the field.
std::optional<sim::Vec3> parseVec(const QString& text, const QString& field, QString& why) {
    QString t = text;
    const QStringList parts = t.replace(',', ' ').split(' ', Qt::SkipEmptyParts);
    if (parts.size() != 3) {
        why = QObject::tr("%1: '%2' is not three numbers x, y, z").arg(field, text);
        return std::nullopt;
    }
    sim::Vec3 v;
    for (int k = 0; k < 3; ++k) {
        const auto x = parseNumberText(parts[k], field, why);
        if (!x) return std::nullopt;
        v[k] = *x;
    }
    return v;
}

/// A name new among the primitives (the reader checks bodies and surfaces too).
std::string freeName(const std::string& base, const std::vector<SceneryProject>& scenery) {
    std::string name = base;
    for (int n = 2;
         std::any_of(scenery.begin(), scenery.end(), [&](const SceneryProject& s) { return s.name == name; }); ++n)
        name = base + "_" + std::to_string(n);
    return name;
}

} // namespace

SurroundingsPanel::SurroundingsPanel(Document* doc, QWidget* parent) : QWidget(parent), m_doc(doc) {
    auto* layout = new QVBoxLayout(this);
    m_list = new QListWidget(this);
    m_list->setObjectName("sceneryList");
    m_list->setMaximumHeight(110);
    layout->addWidget(m_list);
    auto* buttons = new QHBoxLayout;
    m_addWall = new QPushButton(tr("Add wall"), this);
    m_addWall->setObjectName("addSceneryWall");
    m_addWall->setToolTip(tr("A cylinder wall seen from inside (the pelvis, the abdominal wall)"));
    m_addFloor = new QPushButton(tr("Add floor"), this);
    m_addFloor->setObjectName("addSceneryFloor");
    m_addFloor->setToolTip(tr("A disc (the floor below the organs, an end wall)"));
    m_remove = new QPushButton(tr("Remove"), this);
    m_remove->setObjectName("removeScenery");
    m_import = new QPushButton(tr("Import mesh…"), this);
    m_import->setObjectName("importScenery");
    m_import->setToolTip(tr("Static anatomy from a surface file (OBJ, STL, PLY, glTF, FBX), drawn as it is"));
    m_maps = new QPushButton(tr("Material maps…"), this);
    m_maps->setObjectName("sceneryMaps");
    m_maps->setToolTip(tr("The selected surrounding's texture: spec, tiles per metre, normal strength"));
    for (QPushButton* b : {m_addWall, m_addFloor, m_import, m_remove, m_maps})
        buttons->addWidget(b);
    buttons->addStretch(1);
    layout->addLayout(buttons);
    auto* form = new QFormLayout;
    const std::pair<const char*, QString> keys[] = {
        {"name", tr("Name")},         {"radius_mm", tr("Radius (mm)")}, {"start", tr("Axis start (m)")},
        {"end", tr("Axis end (m)")},  {"from_deg", tr("Arc from (°)")}, {"to_deg", tr("Arc to (°)")},
        {"center", tr("Centre (m)")}, {"normal", tr("Normal")},         {"scale", tr("Metres per file unit")}};
    for (const auto& [key, label] : keys) {
        auto* e = new QLineEdit(this);
        e->setObjectName(QString("scenery_") + key);
        form->addRow(label, e);
        m_fields[key] = e;
        connect(e, &QLineEdit::editingFinished, this, [this, k = QString(key)] { typed(k); });
    }
    m_facing = new QComboBox(this);
    m_facing->setObjectName("scenery_facing");
    m_facing->addItems({tr("inward"), tr("outward")});
    form->addRow(tr("Facing"), m_facing);
    layout->addLayout(form);
    m_error = new QLabel(this);
    m_error->setObjectName("sceneryError");
    m_error->setWordWrap(true);
    m_error->setStyleSheet("color: #b00");
    layout->addWidget(m_error);
    layout->addStretch(1);
    connect(m_facing, &QComboBox::currentIndexChanged, this, [this] { typed("facing"); });
    connect(m_list, &QListWidget::currentRowChanged, this, [this](int row) {
        if (m_filling) return;
        m_selected = row;
        fill();
        emit selectedChanged(m_selected);
    });
    connect(m_maps, &QPushButton::clicked, this, [this] {
        if (m_selected >= 0) emit mapsRequested(m_selected);
    });
    connect(m_addWall, &QPushButton::clicked, this, [this] { add(true); });
    connect(m_addFloor, &QPushButton::clicked, this, [this] { add(false); });
    connect(m_import, &QPushButton::clicked, this, &SurroundingsPanel::askImport);
    connect(m_remove, &QPushButton::clicked, this, &SurroundingsPanel::remove);
    connect(m_doc, &Document::changed, this, [this](const Change&) { fill(); });
    fill();
}

QLineEdit* SurroundingsPanel::field(const QString& key) const {
    const auto it = m_fields.find(key);
    return it == m_fields.end() ? nullptr : it->second;
}

void SurroundingsPanel::fill() {
    m_filling = true;
    const std::vector<SceneryProject> none;
    const auto& scenery = m_doc->hasProject() ? m_doc->project().scenery : none;
    m_list->clear();
    for (const SceneryProject& s : scenery) {
        const bool wall = s.generator == SceneryProject::Generator::Cylinder;
        const bool file = s.generator == SceneryProject::Generator::File;
        m_list->addItem(QString::fromStdString(s.name) + " — " +
                        (file   ? tr("imported %1").arg(QString::fromStdString(s.file.filename().string()))
                         : wall ? (s.inward ? tr("wall, seen from inside") : tr("cylinder, outward"))
                                : tr("disc")));
    }
    if (m_selected >= static_cast<int>(scenery.size())) m_selected = static_cast<int>(scenery.size()) - 1;
    m_list->setCurrentRow(m_selected);
    const SceneryProject* s = m_selected >= 0 ? &scenery[static_cast<size_t>(m_selected)] : nullptr;
    const bool wall = s && s->generator == SceneryProject::Generator::Cylinder;
    const bool file = s && s->generator == SceneryProject::Generator::File;
    const std::map<QString, QString> text = {{"name", s ? QString::fromStdString(s->name) : QString()},
                                             {"radius_mm", s ? numberText(s->radius * 1e3) : QString()},
                                             {"start", wall ? vecText(s->start) : QString()},
                                             {"end", wall ? vecText(s->end) : QString()},
                                             {"from_deg", wall ? numberText(s->fromDeg) : QString()},
                                             {"to_deg", wall ? numberText(s->toDeg) : QString()},
                                             {"center", s && !wall && !file ? vecText(s->center) : QString()},
                                             {"normal", s && !wall && !file ? vecText(s->normal) : QString()},
                                             {"scale", file ? numberText(s->scale) : QString()}};
    for (const auto& [key, e] : m_fields) {
        e->setText(text.at(key));
        const bool wallOnly = key == "start" || key == "end" || key == "from_deg" || key == "to_deg";
        const bool discOnly = key == "center" || key == "normal";
        const bool shape = key != "name" && key != "scale"; // a primitive's geometry
        e->setEnabled(s && (!wallOnly || wall) && (!discOnly || !wall) && (key != "scale" || file) &&
                      (!shape || !file));
    }
    m_facing->setCurrentIndex(s && !s->inward ? 1 : 0);
    m_facing->setEnabled(wall);
    m_remove->setEnabled(s != nullptr);
    m_maps->setEnabled(s != nullptr);
    m_filling = false;
}

void SurroundingsPanel::typed(const QString& key) {
    if (m_filling || !m_doc->hasProject() || m_selected < 0) return;
    std::vector<SceneryProject> scenery = m_doc->project().scenery;
    if (m_selected >= static_cast<int>(scenery.size())) return;
    SceneryProject& s = scenery[static_cast<size_t>(m_selected)];
    const QString field = QString("scenery[%1].%2").arg(m_selected).arg(key);
    const QString t = key == "facing" ? QString() : m_fields.at(key)->text();
    QString why;
    if (key == "name") {
        s.name = t.trimmed().toStdString();
    } else if (key == "scale") {
        const auto v = parseNumberText(t, field, why);
        if (!v) return show(why);
        s.scale = *v;
    } else if (key == "radius_mm" || key == "from_deg" || key == "to_deg") {
        const auto v = parseNumberText(t, field, why);
        if (!v) return show(why);
        (key == "radius_mm" ? s.radius : key == "from_deg" ? s.fromDeg : s.toDeg) = key == "radius_mm" ? *v / 1e3 : *v;
    } else if (key == "facing") {
        s.inward = m_facing->currentIndex() == 0;
    } else {
        const auto v = parseVec(t, field, why);
        if (!v) return show(why);
        (key == "start" ? s.start : key == "end" ? s.end : key == "center" ? s.center : s.normal) = *v;
    }
    const std::filesystem::path& dir = m_doc->project().dir;
    if (sceneryJson(scenery, dir) == sceneryJson(m_doc->project().scenery, dir)) return; // nothing changed: no step
    show(m_doc->editScenery(tr("Surroundings: %1 %2").arg(QString::fromStdString(s.name), key), scenery,
                            m_doc->project().sceneryTextures));
}

void SurroundingsPanel::add(bool wall) {
    if (!m_doc->hasProject()) return;
    std::vector<SceneryProject> scenery = m_doc->project().scenery;
    std::vector<std::optional<TextureProject>> textures = m_doc->project().sceneryTextures;
    SceneryProject s;
    s.generator = wall ? SceneryProject::Generator::Cylinder : SceneryProject::Generator::Disc;
    s.name = freeName(wall ? "wall" : "floor", scenery);
    if (wall) { // about the x axis, 8 cm round, seen from inside
        s.start = sim::Vec3(-0.1, 0, 0);
        s.end = sim::Vec3(0.1, 0, 0);
        s.radius = 0.08;
    } else { // 5 cm below the origin, facing up
        s.center = sim::Vec3(0, 0, -0.05);
        s.normal = sim::Vec3::UnitZ();
        s.radius = 0.1;
    }
    scenery.push_back(s);
    textures.resize(scenery.size());
    const QString why = m_doc->editScenery(tr("Add %1").arg(QString::fromStdString(s.name)), scenery, textures);
    if (why.isEmpty()) m_selected = static_cast<int>(scenery.size()) - 1;
    show(why);
    fill();
    if (why.isEmpty()) emit selectedChanged(m_selected);
}

void SurroundingsPanel::askImport() {
    if (!m_doc->hasProject()) return;
    openAnatomyDialog(this, m_doc->folder(), tr("Import a mesh as surrounding anatomy"),
                      tr("Surfaces (*.obj *.stl *.ply *.gltf *.glb *.fbx)"), "sceneryImportDialog", false,
                      [this](const QStringList& files) {
                          if (!files.isEmpty()) importFile(files.front());
                      });
}

QString SurroundingsPanel::importFile(const QString& path) {
    if (!m_doc->hasProject()) return tr("no project is open");
    QString why;
    const QString copied = copyIntoProject(m_doc->folder(), path, &why);
    if (copied.isEmpty()) {
        show(why);
        return why;
    }
    SceneryProject s;
    s.generator = SceneryProject::Generator::File;
    s.file = copied.toStdString();
    try { // the unit from the size, as Import anatomy guesses it
        const sim::TriMesh m = bake::importSurface(s.file);
        sim::Vec3 lo = sim::Vec3::Constant(INFINITY), hi = -lo;
        for (const sim::Vec3& x : m.positions()) {
            lo = lo.cwiseMin(x);
            hi = hi.cwiseMax(x);
        }
        const double extent = (hi - lo).maxCoeff();
        const bake::LengthUnit unit = bake::guessLengthUnit(extent);
        s.scale = bake::metresPerUnit(unit);
        m_guess = tr("'%1': %2 units long: looks like %3 (%4 m per unit)")
                      .arg(QFileInfo(path).fileName(), numberText(extent),
                           QString::fromUtf8(bake::unitLongName(unit).data(), int(bake::unitLongName(unit).size())),
                           numberText(s.scale));
    } catch (const std::exception& e) {
        show(QString::fromStdString(e.what()));
        return m_error->text();
    }
    std::vector<SceneryProject> scenery = m_doc->project().scenery;
    std::vector<std::optional<TextureProject>> textures = m_doc->project().sceneryTextures;
    s.name = freeName(QFileInfo(path).completeBaseName().toStdString(), scenery);
    scenery.push_back(s);
    textures.resize(scenery.size());
    why = m_doc->editScenery(tr("Import %1").arg(QString::fromStdString(s.name)), scenery, textures);
    if (why.isEmpty()) m_selected = static_cast<int>(scenery.size()) - 1;
    show(why);
    fill();
    if (why.isEmpty()) emit selectedChanged(m_selected);
    return why;
}

void SurroundingsPanel::remove() {
    if (!m_doc->hasProject() || m_selected < 0) return;
    std::vector<SceneryProject> scenery = m_doc->project().scenery;
    std::vector<std::optional<TextureProject>> textures = m_doc->project().sceneryTextures;
    if (m_selected >= static_cast<int>(scenery.size())) return;
    const std::string name = scenery[static_cast<size_t>(m_selected)].name;
    scenery.erase(scenery.begin() + m_selected);
    textures.resize(std::max(textures.size(), scenery.size() + 1));
    textures.erase(textures.begin() + m_selected);
    show(m_doc->editScenery(tr("Remove %1").arg(QString::fromStdString(name)), scenery, textures));
}

void SurroundingsPanel::show(const QString& why) {
    m_error->setText(why);
    if (!why.isEmpty()) fill(); // the model's values again
}

} // namespace viscera::studio
