#pragma once
/// Fit to test data [A §4.3.3]: a two-column text/CSV file of a uniaxial test (stretch or
/// engineering strain; nominal stress in Pa) and, optionally, a second test of the same material
/// (equibiaxial or planar shear, the same format), fitted together by least squares of the
/// curves' control values under their shape rule (sim::fitUniaxial). Shows the data over the fitted response
/// with SSE, R², the largest relative error and the stretch range the data covers, and what the
/// fit changed and left (small-strain E and ν: f′ alone, the default, keeps ν where the artist put
/// it, sim::FitCurves::FPrimeKeepingPoisson, with one test or two; a material without an h′ keeps
/// its volume stiffness instead, and says so; "f′ and h′" fits ν too); Apply writes the
/// fitted curves into the body's material as one undo step. A fit whose material would be
/// unstable (no uniaxial state, a stress that falls with stretch over 0.6–1.6 and the data's
/// range, E or ν out of range) is shown but cannot be applied, with the reason. Enter runs the
/// fit; editing the file name drops the previous fit. A bad file is refused with the reader's
/// one line (file, line, column, rule).
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

    QLineEdit* secondFileField() { return m_secondFile; }
    QComboBox* secondCaseBox() { return m_secondCase; }

private:
    /// The uniaxial file's rows and, when named, the second test's (combined, each row marked).
    sim::UniaxialData readData() const;
    sim::LoadCase secondCase() const;
    /// fitUniaxial from `start`; with two tests and h′ free also from Neo-Hookean curves at several
    /// ν (the fit is local), the smallest SSE kept (m_startNote says which start won).
    sim::CurveFitResult bestFit(const sim::ValanisLandelCurves& start, const sim::UniaxialData& data,
                                const sim::FitOptions& opt);
    /// The data of each test as points, and the fitted response in the second test.
    void secondTestSeries(const sim::CurveFitResult& r, std::vector<PlotWidget::Series>& series) const;
    /// f′ alone keeps ν (FitCurves::FPrimeKeepingPoisson) when the curves have an h′ rising at 1.
    static bool keepsPoisson(const sim::ValanisLandelCurves& curves);
    /// What the fit changed and what it left: small-strain E and ν before and after.
    QString changesText(const sim::ValanisLandelCurves& before, const sim::ValanisLandelCurves& after) const;
    /// The fitted response into `fit`; the reason the fitted material would be unstable (no
    /// uniaxial state, a falling stress, E or ν out of range), empty when it is not.
    QString fittedResponse(const sim::CurveFitResult& r, PlotWidget::Series& fit) const;

    Document* m_doc;
    int m_body;
    QLineEdit* m_file;
    QComboBox *m_measure, *m_curves;
    QLineEdit* m_secondFile = nullptr;
    QComboBox* m_secondCase = nullptr;
    QString m_startNote;
    QLabel* m_result;
    PlotWidget* m_plot;
    QPushButton *m_fitButton, *m_apply;
    std::optional<sim::CurveFitResult> m_fitResult;
    std::optional<sim::UniaxialData> m_data;
};

} // namespace viscera::studio
