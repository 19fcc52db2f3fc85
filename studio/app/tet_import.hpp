#pragma once
/// File → Import tet mesh… [issue 57 item 7]: a tetrahedral mesh made elsewhere (Gmsh .msh,
/// VTK .vtu, .vtet) becomes a tet body as it is: no remeshing, no meshing. The file is read with
/// its rules (sim::readTetFile: linear tetrahedra only, ASCII, one line naming the file, the line
/// and the rule); its unit is asked, starting at the guess from its size (bake::guessLengthUnit,
/// as Import anatomy does: a liver 28 units long looks like centimetres); the file is copied into
/// the project's anatomy/ folder and the body added as one undo step — named after the file
/// (new among the bodies), mesh {"file": ..., "scale": metres per unit}, the first body's
/// material — and selected. A refused file leaves the project unchanged.
#include "bake/import.hpp"

#include <QObject>
#include <QString>
#include <optional>

class QAction;
class QWidget;

namespace viscera::studio {

class Document;
class Selection;

class TetImport : public QObject {
    Q_OBJECT
public:
    TetImport(Document* doc, Selection* sel, QWidget* window);
    QAction* action() { return m_action; }
    /// What the unit question says of `file` (tets, extent in file units, the guess), or none
    /// with the refusal in `why`.
    struct Probe {
        size_t tets = 0, nodes = 0;
        double extent = 0; ///< longest bounding-box edge, file units
        bake::LengthUnit guess = bake::LengthUnit::Metre;
    };
    static std::optional<Probe> probe(const QString& file, QString* why);
    /// Adds `file` in `unit` as a tet body (one undo step); returns the refusal, empty when done.
    QString importFile(const QString& file, bake::LengthUnit unit);

signals:
    void logMessage(const QString& line);
    void failed(const QString& line);

private:
    void ask();
    void askUnit(const QString& file);
    /// Copies `file` in and adds the body, `probed` being what probe() read of it.
    QString add(const QString& file, bake::LengthUnit unit, const Probe& probed);

    Document* m_doc;
    Selection* m_sel;
    QWidget* m_window;
    QAction* m_action = nullptr;
};

} // namespace viscera::studio
