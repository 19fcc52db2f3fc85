#include "app/project_tree_panel.hpp"

#include "app/instrument_panel.hpp"

#include "sim/material/material.hpp"

#include <QAction>
#include <QHeaderView>
#include <QKeyEvent>
#include <QMenu>
#include <QMessageBox>
#include <QMetaMethod>
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

    // Renaming and deleting a body [issue 57 item 7]: the body items' context menu, F2 and Delete.
    m_rename = new QAction(tr("Rename body…"), this);
    m_rename->setObjectName("renameBodyAction");
    m_rename->setShortcut(QKeySequence(Qt::Key_F2));
    m_delete = new QAction(tr("Delete body"), this);
    m_delete->setObjectName("deleteBodyAction");
    m_delete->setShortcut(QKeySequence(Qt::Key_Delete));
    for (QAction* a : {m_rename, m_delete}) {
        a->setShortcutContext(Qt::WidgetShortcut); // only while the tree has the focus
        a->setShortcutVisibleInContextMenu(true);
        addAction(a);
    }
    connect(m_rename, &QAction::triggered, this, &ProjectTreePanel::startRename);
    connect(m_delete, &QAction::triggered, this, &ProjectTreePanel::deleteCurrentBody);
    m_addLayer = new QAction(tr("Add tissue layer"), this);
    m_addLayer->setObjectName("addLayerAction");
    m_deleteLayer = new QAction(tr("Delete tissue layer"), this);
    m_deleteLayer->setObjectName("deleteLayerAction");
    connect(m_addLayer, &QAction::triggered, this, &ProjectTreePanel::addLayerToCurrentBody);
    connect(m_deleteLayer, &QAction::triggered, this, &ProjectTreePanel::deleteCurrentLayer);
    connect(this, &QTreeWidget::currentItemChanged, this, &ProjectTreePanel::updateActions);
    setContextMenuPolicy(Qt::CustomContextMenu);
    connect(this, &QWidget::customContextMenuRequested, this, [this](const QPoint& at) {
        QTreeWidgetItem* item = itemAt(at);
        const int kind = item ? item->data(0, kKindRole).toInt() : -1;
        if (kind != kindValue(Selection::Kind::Body) && kind != kindValue(Selection::Kind::Surface)) return;
        setCurrentItem(item);
        QMenu menu(this);
        if (kind == kindValue(Selection::Kind::Body)) {
            menu.addAction(m_rename);
            menu.addAction(m_delete);
            menu.addAction(m_addLayer);
        } else {
            menu.addAction(m_deleteLayer);
        }
        menu.exec(viewport()->mapToGlobal(at));
    });
    updateActions();
}

int ProjectTreePanel::currentBody() const {
    const QTreeWidgetItem* item = currentItem();
    if (!item || item->data(0, kKindRole).toInt() != kindValue(Selection::Kind::Body)) return -1;
    return item->data(0, kIndexRole).toInt();
}

int ProjectTreePanel::currentLayer() const {
    const QTreeWidgetItem* item = currentItem();
    if (!item || item->data(0, kKindRole).toInt() != kindValue(Selection::Kind::Surface)) return -1;
    return item->data(0, kIndexRole).toInt();
}

void ProjectTreePanel::updateActions() {
    const bool body = currentBody() >= 0;
    m_rename->setEnabled(body);
    m_delete->setEnabled(body);
    m_addLayer->setEnabled(body);
    m_deleteLayer->setEnabled(currentLayer() >= 0);
}

void ProjectTreePanel::keyPressEvent(QKeyEvent* event) {
    // the keys of the actions when no shortcut took them (the window not active)
    if (currentBody() >= 0 && event->key() == Qt::Key_F2 && event->modifiers() == Qt::NoModifier) {
        startRename();
        return event->accept();
    }
    if (currentBody() >= 0 && event->key() == Qt::Key_Delete && event->modifiers() == Qt::NoModifier) {
        deleteCurrentBody();
        return event->accept();
    }
    if (currentLayer() >= 0 && event->key() == Qt::Key_Delete && event->modifiers() == Qt::NoModifier) {
        deleteCurrentLayer();
        return event->accept();
    }
    QTreeWidget::keyPressEvent(event);
}

void ProjectTreePanel::startRename() {
    const int body = currentBody();
    if (body < 0 || !m_doc->hasProject()) return;
    if (m_renameDialog) m_renameDialog->close();
    const QString from = QString::fromStdString(m_doc->project().bodies.at(static_cast<size_t>(body)).scene.name);
    auto* dialog = new QInputDialog(this);
    dialog->setObjectName("renameBodyDialog");
    dialog->setAttribute(Qt::WA_DeleteOnClose);
    dialog->setWindowTitle(tr("Rename body"));
    dialog->setLabelText(tr("New name of body '%1' (1-64 characters of A-Z a-z 0-9 _ -):").arg(from));
    dialog->setTextValue(from);
    connect(dialog, &QInputDialog::textValueSelected, this, [this, from](const QString& name) {
        // the body by its name: an undo while the dialog was open may have moved it
        int index = -1;
        for (size_t i = 0; m_doc->hasProject() && i < m_doc->project().bodies.size() && index < 0; ++i)
            if (m_doc->project().bodies[i].scene.name == from.toStdString()) index = static_cast<int>(i);
        report(index < 0 ? tr("body '%1' is gone; nothing renamed").arg(from) : m_doc->renameBody(index, name));
    });
    m_renameDialog = dialog;
    dialog->open();
}

void ProjectTreePanel::deleteCurrentBody() {
    const int body = currentBody();
    if (body < 0) return;
    const QString why = m_doc->removeBody(body);
    if (why.isEmpty() && m_sel->body() >= body) m_sel->clear(); // it named the body gone or one that moved
    report(why);
}

void ProjectTreePanel::addLayerToCurrentBody() {
    const int body = currentBody();
    if (body < 0 || !m_doc->hasProject()) return;
    const QString why = m_doc->addLayer(body);
    if (why.isEmpty()) m_sel->set(Selection::Kind::Surface, static_cast<int>(m_doc->project().surfaces.size()) - 1);
    report(why);
}

void ProjectTreePanel::deleteCurrentLayer() {
    const int layer = currentLayer();
    if (layer < 0) return;
    const QString why = m_doc->removeLayer(layer);
    if (why.isEmpty() && m_sel->surface() >= layer) m_sel->clear();
    report(why);
}

void ProjectTreePanel::report(const QString& why) {
    m_refusal = why;
    if (why.isEmpty()) return;
    if (isSignalConnected(QMetaMethod::fromSignal(&ProjectTreePanel::refused))) return emit refused(why);
    emit m_doc->logMessage(why); // nobody shows it: the log, and a message box
    auto* box = new QMessageBox(QMessageBox::Warning, tr("Body not changed"), why, QMessageBox::Ok, this);
    box->setObjectName("bodyEditRefusal");
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->open();
}

void ProjectTreePanel::onChanged(const Change& what) {
    // the tree lists the instruments: a scene edit (add, remove, rename) rebuilds it too
    if (what.touches(Change::Structure) || what.touches(Change::Scene)) return rebuild();
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
        QTreeWidgetItem* surroundings = group(tr("Surroundings"), kGroup); // render-only scenery
        for (const SceneryProject& sc : p.scenery)
            leaf(surroundings, QString::fromStdString(sc.name),
                 sc.generator == SceneryProject::Generator::Disc   ? tr("disc")
                 : sc.generator == SceneryProject::Generator::File ? tr("imported mesh")
                                                                   : tr("wall"),
                 kGroup, -1);
        QTreeWidgetItem* instruments = group(tr("Instruments"), kGroup);
        if (p.scene.interaction)
            for (size_t t = 0; t < p.scene.interaction->instruments.size(); ++t) {
                const auto& in = p.scene.interaction->instruments[t];
                const QString kind = instrumentKindLabel(in.kind);
                leaf(instruments, QString::fromStdString(in.name),
                     tr("%1, %2 hand").arg(kind, QString::fromStdString(in.device.hand)), kindValue(K::Instrument),
                     static_cast<int>(t));
            }
        if (p.scene.suture) leaf(instruments, tr("needle"), tr("suture trajectory"), kGroup, -1);
        group(tr("Render settings"), kindValue(K::Render));
        group(tr("Solver (%1)").arg(QString::fromStdString(p.scene.solverType)), kindValue(K::Solver));
        expandAll();
    }
    m_rebuilding = false;
    follow();
    updateActions();
}

} // namespace viscera::studio
