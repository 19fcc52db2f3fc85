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
/// or, when nothing listens, shown in a message box.
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
    void report(const QString& why);

    Document* m_doc;
    Selection* m_sel;
    QAction* m_rename = nullptr;
    QAction* m_delete = nullptr;
    QPointer<QInputDialog> m_renameDialog;
    QString m_refusal;
    bool m_rebuilding = false;
    int m_builds = 0;
};

} // namespace viscera::studio
