#pragma once
/// The project tree: bodies, materials, surfaces, instruments, render settings and solver of the
/// open project. A click selects (the one Selection); the tree follows the selection made
/// elsewhere (the viewport) without acting on it. It is rebuilt when the project's structure
/// changes; a material edit only renews the material leaf's model name (a curve drag rebuilds
/// nothing).
#include "app/document.hpp"
#include "app/selection.hpp"

#include <QTreeWidget>

namespace viscera::studio {

class ProjectTreePanel : public QTreeWidget {
    Q_OBJECT
public:
    ProjectTreePanel(Document* doc, Selection* selection, QWidget* parent = nullptr);

    /// How many times the tree was built (a test checks that a drag builds none).
    int builds() const { return m_builds; }

private:
    void rebuild();
    void onChanged(const Change& what);
    void follow();

    Document* m_doc;
    Selection* m_sel;
    bool m_rebuilding = false;
    int m_builds = 0;
};

} // namespace viscera::studio
