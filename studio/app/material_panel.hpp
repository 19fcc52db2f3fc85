#pragma once
/// The curve-based material editor of one body [A §4.3.3, Fig. 4.5–4.7]: the f′, g′ and h′
/// curves of its Valanis–Landel material, presets from a law and (E, ν), the rest
/// normalization (Ψ(1,1,1) and the stress at rest, shown live), the selected point's typed
/// coordinates, and beside the curves the material's response: nominal stress against stretch
/// in uniaxial tension and compression, and shear stress in simple shear.
///
/// Every change is a Document edit (one undo step; a drag is one step however many events it
/// has) checked by the rules of export.
#include "app/curve_editor.hpp"
#include "app/plot_widget.hpp"
#include "sim/material/material.hpp"
#include "sim/material/valanis_landel.hpp"

#include <QWidget>

#include <optional>

class QComboBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QVBoxLayout;

namespace viscera::studio {

class Document;

class MaterialPanel : public QWidget {
    Q_OBJECT
public:
    explicit MaterialPanel(Document* doc, QWidget* parent = nullptr);

    /// The body whose material is edited (-1: none).
    void setBody(int index);
    int body() const { return m_body; }
    CurveEditor* editor(int k) { return m_editors[k]; } ///< 0 f′, 1 g′, 2 h′
    PlotWidget* uniaxialPlot() { return m_uniaxial; }
    PlotWidget* shearPlot() { return m_shear; }
    QLabel* restLabel() { return m_rest; }
    QLabel* statusLabel() { return m_status; }
    QLineEdit* pointX() { return m_x; }
    QLineEdit* pointY() { return m_y; }
    QComboBox* presetLaw() { return m_law; }
    QLineEdit* presetE() { return m_E; }
    QLineEdit* presetNu() { return m_nu; }
    QPushButton* fitButton() { return m_fit; }

    /// Replaces the body's material by the editable curves of `law` at (E, ν). Returns the
    /// error (empty when applied).
    QString applyPreset(const QString& law, double E, double nu);
    /// Sets the selected point of the editor that has the focus to the typed x and y fields.
    QString applyTypedPoint();
    /// Curve-wide edits of curve k (0 f′, 1 g′, 2 h′), each one undo step; the error, or empty.
    /// Scale: every value's distance from the rest value times `factor` (> 0; the rest point and
    /// the order stay). Smooth: each free point halfway towards the line through its neighbours
    /// (the order stays). Reset: the curve of the preset law chosen above at the body's E and ν.
    QString scaleCurve(int k, double factor);
    QString smoothCurve(int k);
    QString resetCurve(int k);
    /// The editor the curve-wide buttons and the typed point act on (the one last clicked).
    int activeCurve() const { return m_active; }

    /// The curves of a Valanis–Landel material with explicit curves (nullopt otherwise).
    static std::optional<sim::ValanisLandelCurves> curvesOf(const sim::Material& m);

signals:
    void fitRequested(int body);

private:
    void refresh();
    void connectEditor(int k);
    QString editPoints(int k, const QString& text, const std::function<void(std::vector<std::array<double, 2>>&)>& fn,
                       int mergeKey = 0);
    void showSelected();
    void setStatus(const QString& error);

    Document* m_doc;
    int m_body = -1;
    int m_active = 0; ///< editor the typed point refers to
    int m_dragKey = 0;
    CurveEditor* m_editors[3] = {};
    PlotWidget *m_uniaxial = nullptr, *m_shear = nullptr;
    QLabel *m_rest = nullptr, *m_status = nullptr, *m_header = nullptr;
    QLineEdit *m_x = nullptr, *m_y = nullptr, *m_E = nullptr, *m_nu = nullptr;
    QComboBox* m_law = nullptr;
    QPushButton *m_applyPreset = nullptr, *m_fit = nullptr;
    QLineEdit* m_scale = nullptr;
    void buildCurveRow(QVBoxLayout* root);
};

} // namespace viscera::studio
