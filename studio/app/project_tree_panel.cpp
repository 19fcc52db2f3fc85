#include "app/project_tree_panel.hpp"

#include "sim/material/material.hpp"

#include <QHeaderView>
#include <QTreeWidgetItemIterator>

namespace viscera::studio {
namespace {

/// Tree items carry what they select: a Selection::Kind (or kGroup, kMaterial) and an index.
constexpr int kKindRole = Qt::UserRole, kIndexRole = Qt::UserRole + 1;
constexpr int kGroup = -1, kMaterial = -2; // a material leaf selects its body

int kindValue(Selection::Kind k) {
    return static_cast<int>(k);
}

} // namespace

ProjectTreePanel::ProjectTreePanel(Document* doc, Selection* selection, QWidget* parent)
    : QTreeWidget(parent), m_doc(doc), m_sel(selection) {
    setObjectName("projectTree");
    setHeaderLabels({tr("Project"), tr("")});
    header()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
    connect(this, &QTreeWidget::currentItemChanged, this, [this](QTreeWidgetItem* item) {
        if (m_rebuilding || !item) return;
        const int kind = item->data(0, kKindRole).toInt(), index = item->data(0, kIndexRole).toInt();
        if (kind == kMaterial)
            m_sel->set(Selection::Kind::Body, index);
        else if (kind == kGroup)
            m_sel->clear();
        else
            m_sel->set(static_cast<Selection::Kind>(kind), index);
    });
    connect(m_doc, &Document::changed, this, &ProjectTreePanel::onChanged);
    connect(m_sel, &Selection::changed, this, &ProjectTreePanel::follow);
}

void ProjectTreePanel::onChanged(const Change& what) {
    if (what.touches(Change::Structure)) return rebuild();
    if (!what.touches(Change::Material) || !m_doc->hasProject()) return;
    // a material edit: the material leaves' model names, in place
    const auto& bodies = m_doc->project().bodies;
    for (QTreeWidgetItemIterator it(this); *it; ++it) {
        const int index = (*it)->data(0, kIndexRole).toInt();
        if ((*it)->data(0, kKindRole).toInt() != kMaterial || index < 0 || index >= static_cast<int>(bodies.size()))
            continue;
        const QString model = QString::fromStdString(sim::materialModelName(bodies[index].scene.material.model));
        if ((*it)->text(1) != model) (*it)->setText(1, model);
    }
}

void ProjectTreePanel::follow() {
    m_rebuilding = true; // the tree follows without selecting again
    const int kind = kindValue(m_sel->kind()), index = m_sel->index();
    QTreeWidgetItem* found = nullptr;
    for (QTreeWidgetItemIterator it(this); *it && !found; ++it)
        if ((*it)->data(0, kKindRole).toInt() == kind && (*it)->data(0, kIndexRole).toInt() == index) found = *it;
    if (found)
        setCurrentItem(found);
    else
        setCurrentItem(nullptr);
    m_rebuilding = false;
}

void ProjectTreePanel::rebuild() {
    ++m_builds;
    m_rebuilding = true;
    clear();
    if (m_doc->hasProject()) {
        const Project& p = m_doc->project();
        using K = Selection::Kind;
        auto group = [&](const QString& name, int kind) {
            auto* g = new QTreeWidgetItem(this, {name});
            g->setData(0, kKindRole, kind);
            g->setData(0, kIndexRole, -1);
            return g;
        };
        auto leaf = [&](QTreeWidgetItem* g, const QString& name, const QString& info, int kind, int index) {
            auto* it = new QTreeWidgetItem(g, {name, info});
            it->setData(0, kKindRole, kind);
            it->setData(0, kIndexRole, index);
        };
        QTreeWidgetItem* bodies = group(tr("Bodies"), kGroup);
        QTreeWidgetItem* materials = group(tr("Materials"), kGroup);
        for (size_t i = 0; i < p.bodies.size(); ++i) {
            const auto& b = p.bodies[i].scene;
            leaf(bodies, QString::fromStdString(b.name), tr("tet body"), kindValue(K::Body), static_cast<int>(i));
            leaf(materials, QString::fromStdString(b.name) + tr(" material"),
                 QString::fromStdString(sim::materialModelName(b.material.model)), kMaterial, static_cast<int>(i));
        }
        QTreeWidgetItem* surfaces = group(tr("Surfaces"), kGroup);
        for (size_t s = 0; s < p.surfaces.size(); ++s)
            leaf(surfaces, QString::fromStdString(p.surfaces[s].scene.name),
                 tr("on %1").arg(QString::fromStdString(p.surfaces[s].scene.attachTo)), kindValue(K::Surface),
                 static_cast<int>(s));
        QTreeWidgetItem* instruments = group(tr("Instruments"), kGroup);
        if (p.scene.interaction)
            for (size_t t = 0; t < p.scene.interaction->instruments.size(); ++t)
                leaf(instruments, QString::fromStdString(p.scene.interaction->instruments[t].name), tr("scripted"),
                     kindValue(K::Instrument), static_cast<int>(t));
        if (p.scene.suture) leaf(instruments, tr("needle"), tr("suture trajectory"), kGroup, -1);
        group(tr("Render settings"), kindValue(K::Render));
        group(tr("Solver (%1)").arg(QString::fromStdString(p.scene.solverType)), kindValue(K::Solver));
        expandAll();
    }
    m_rebuilding = false;
    follow();
}

} // namespace viscera::studio
