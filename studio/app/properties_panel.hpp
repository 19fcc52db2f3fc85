#pragma once
/// The properties of the selection: a body's material model, E, ν and density (and, for a body
/// made from anatomy, its parts' unit, scale and rotation; for a body meshed from a surface, its
/// triangle and tet sizes in mm; where it is held: the Hold tissue tool,
/// its margin and Release holds, hold_tool.hpp); the solver's dt,
/// substeps, iterations and damping; the render settings and a surface's figures. A typed value
/// is one undo step through the Document (a material value as a typed material edit, checked by
/// the reader's material rules); a refused value shows the rule under the fields and the field
/// shows the model's value again. The fields are made anew when the selection or the project's
/// structure changes, and take the model's values in place after an edit (a curve drag makes no
/// widget).
#include "app/document.hpp"
#include "app/selection.hpp"

#include <QWidget>

class QFormLayout;
class QLabel;

namespace viscera::studio {

class HoldTool;
class MaterialPanel;

class PropertiesPanel : public QWidget {
    Q_OBJECT
public:
    PropertiesPanel(Document* doc, Selection* selection, MaterialPanel* material, QWidget* parent = nullptr);

    /// Sets a field of the selection as if typed (name as the field's object name, e.g.
    /// "youngs_modulus", "substeps", "model"). Returns the error shown, empty when accepted.
    QString setProperty(const QString& field, const QString& text);
    QLabel* errorLabel() { return m_error; }
    /// The tool a body's hold rows drive (none: no hold rows).
    void setHoldTool(HoldTool* tool) { m_hold = tool; }
    /// How many times the fields were made (a test checks that a drag makes none).
    int builds() const { return m_builds; }

signals:
    void logMessage(const QString& line);

private:
    /// The fields are made on the next pass of the event loop: an edit often comes from one of
    /// those fields' own signals, which must not delete it.
    void scheduleRebuild();
    void rebuild();
    /// The model's values into the fields that show them (a field being typed in keeps its text
    /// unless `force`).
    void fillValues(bool force);
    QString setMaterialValue(const QString& field, const QString& text);
    QString setSolverValue(const QString& field, double v, const QString& text);
    /// A meshed body's facet or cell size (m), one undo step under the reader's rule.
    QString setMeshingValue(const QString& field, double metres);
    /// A tissue layer's stretch_stiffness, areal_density or subdivide, as one undo step checked by
    /// the project reader's rule for surfaces[i].
    QString setSurfaceValue(const QString& field, const QString& text);
    /// Layer `s`'s region corner typed as "x y z" (m); empty text: the whole boundary.
    QString setLayerRegion(int s, const QString& field, const QString& text);
    /// A body made from anatomy: its parts' unit, scale or rotation (Document::editPlacement).
    QString setPlacementValue(const QString& field, const QString& text);
    void addPlacementFields(const bake::ImportPlacement& placement);
    /// A body's hold rows: how many places hold it, the tool's button, its margin, Release holds.
    void addHoldRows(int body);
    void addField(const QString& name, const QString& label);

    Document* m_doc;
    Selection* m_sel;
    MaterialPanel* m_material;
    HoldTool* m_hold = nullptr;
    QFormLayout* m_form = nullptr;
    QLabel* m_error = nullptr;
    bool m_pending = false;
    int m_builds = 0;
};

} // namespace viscera::studio
