#pragma once
/// Fit to test data [A §4.3.3]: a two-column text/CSV file of a uniaxial test (stretch or
/// engineering strain; nominal stress in Pa), fitted by least squares of the curves' control
/// values under their shape rule (sim::fitUniaxial). Shows the data over the fitted response
/// with SSE, R², the largest relative error and the stretch range the data covers; Apply
/// writes the fitted curves into the body's material as one undo step. A bad file is refused
/// with the reader's one line (file, line, column, rule).
#include "app/plot_widget.hpp"
#include "sim/material/curve_fit.hpp"

#include <QDialog>

#include <optional>

class QComboBox;
class QLabel;
class QLineEdit;
class QPushButton;

namespace viscera::studio {

class Document;

class FitDialog : public QDialog {
    Q_OBJECT
public:
    FitDialog(Document* doc, int body, QWidget* parent = nullptr);

    QLineEdit* fileField() { return m_file; }
    QComboBox* measure() { return m_measure; }
    QComboBox* curves() { return m_curves; }
    QLabel* resultLabel() { return m_result; }
    PlotWidget* plot() { return m_plot; }
    QPushButton* fitButton() { return m_fitButton; }
    QPushButton* applyButton() { return m_apply; }
    const std::optional<sim::CurveFitResult>& result() const { return m_fitResult; }

    /// Reads the file named in the field and fits; false with the message shown on failure.
    bool runFit();
    /// Writes the fitted curves into the body's material (a Document edit). Returns the error.
    QString apply();

private:
    Document* m_doc;
    int m_body;
    QLineEdit* m_file;
    QComboBox *m_measure, *m_curves;
    QLabel* m_result;
    PlotWidget* m_plot;
    QPushButton *m_fitButton, *m_apply;
    std::optional<sim::CurveFitResult> m_fitResult;
    std::optional<sim::UniaxialData> m_data;
};

} // namespace viscera::studio
