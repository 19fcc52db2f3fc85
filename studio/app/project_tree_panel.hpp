#pragma once
/// The project tree: bodies, materials, surfaces, instruments, render settings and solver of the
/// open project. A click selects (the one Selection); the tree follows the selection made
/// elsewhere (the viewport) without acting on it. It is rebuilt when the project's structure
/// changes; a material edit only renews the material leaf's model name (a curve drag rebuilds
/// nothing).
///
/// A body item renames and deletes its body [issue 57 item 7]: its context menu ("Rename body…",
/// "Delete body"), F2 and Delete. Each is one undo step through Document::renameBody and
/// Document::removeBody; a refusal (one line naming the field and the rule) is sent as refused(),
/// or, when nothing listens, shown in a message box. Its menu also adds a tissue layer over the
/// body ("Add tissue layer", Document::addLayer); a layer's item deletes it ("Delete tissue layer",
/// its menu and Delete, Document::removeLayer).
#include "app/document.hpp"
#include "app/selection.hpp"

#include <QInputDialog>
#include <QPointer>
#include <QTreeWidget>

class QAction;

namespace viscera::studio {

class ProjectTreePanel : public QTreeWidget {
    Q_OBJECT
public:
    ProjectTreePanel(Document* doc, Selection* selection, QWidget* parent = nullptr);

    /// How many times the tree was built (a test checks that a drag builds none).
    int builds() const { return m_builds; }
    /// The current item's body, -1 when it is not a body item.
    int currentBody() const;
    /// "Rename body…" (F2) and "Delete body" (Delete): act on the current body item, enabled only
    /// when there is one; the body items' context menu shows them.
    QAction* renameBodyAction() const { return m_rename; }
    QAction* deleteBodyAction() const { return m_delete; }
    /// "Add tissue layer": a fascia over the current body's boundary. "Delete tissue layer": the
    /// current layer item's layer.
    QAction* addLayerAction() const { return m_addLayer; }
    QAction* deleteLayerAction() const { return m_deleteLayer; }
    /// The current item's tissue layer (surface), -1 when it is not a layer item.
    int currentLayer() const;
    /// The open rename dialog ("renameBodyDialog", the name typed in, OK renames), or null.
    QInputDialog* renameDialog() const { return m_renameDialog.data(); }
    /// The last refusal of a rename or delete (empty after one that was done).
    const QString& lastRefusal() const { return m_refusal; }

signals:
    /// A rename or delete was refused: `line` names the file, the field and the rule.
    void refused(const QString& line);

protected:
    void keyPressEvent(QKeyEvent* event) override;

private:
    void rebuild();
    void onChanged(const Change& what);
    void follow();
    void updateActions();
    void startRename();
    void deleteCurrentBody();
    void addLayerToCurrentBody();
    void deleteCurrentLayer();
    void report(const QString& why);

    Document* m_doc;
    Selection* m_sel;
    QAction* m_rename = nullptr;
    QAction* m_delete = nullptr;
    QAction* m_addLayer = nullptr;
    QAction* m_deleteLayer = nullptr;
    QPointer<QInputDialog> m_renameDialog;
    QString m_refusal;
    bool m_rebuilding = false;
    int m_builds = 0;
};

} // namespace viscera::studio
