#include "app/fit_dialog.hpp"

#include "app/number_text.hpp"

#include "app/document.hpp"
#include "app/material_panel.hpp"
#include "sim/material/editable_curves.hpp"
#include "sim/material/material_response.hpp"

#include <QAbstractButton>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QVBoxLayout>

namespace viscera::studio {
FitDialog::FitDialog(Document* doc, int body, QWidget* parent) : QDialog(parent), m_doc(doc), m_body(body) {
    setWindowTitle(tr("Fit material curves to a uniaxial test"));
    setObjectName("fitDialog");
    resize(720, 620); // room for the plot and the figures under it
    auto* root = new QVBoxLayout(this);
    auto* form = new QFormLayout;
    auto* fileRow = new QHBoxLayout;
    m_file = new QLineEdit(this);
    m_file->setObjectName("fitFile");
    auto* browse = new QPushButton(tr("Browse…"), this);
    fileRow->addWidget(m_file, 1);
    fileRow->addWidget(browse);
    form->addRow(tr("Test data (two columns)"), fileRow);
    m_measure = new QComboBox(this);
    m_measure->setObjectName("fitMeasure");
    m_measure->addItems({tr("stretch λ = l/L (dimensionless)"), tr("engineering strain ε = (l − L)/L")});
    form->addRow(tr("Column 1"), m_measure);
    form->addRow(tr("Column 2"), new QLabel(tr("nominal stress (force / undeformed area), Pa"), this));
    m_curves = new QComboBox(this);
    m_curves->setObjectName("fitCurves");
    // f′ alone by default: a uniaxial test fixes one function of stretch, and f′ carries it; h′
    // (the volume response, ν) is left as it is unless the artist asks for it
    m_curves->addItems({tr("f′ only (the stretch response; volume stiffness kept)"), tr("f′ and h′ (ν too)")});
    form->addRow(tr("Fit"), m_curves);
    root->addLayout(form);
    m_plot = new PlotWidget(this);
    m_plot->setObjectName("fitPlot");
    m_plot->setTitle(tr("Data and fitted response"));
    m_plot->setAxes(tr("stretch λ"), tr("nominal stress [Pa]"));
    m_plot->setMinimumSize(420, 260);
    root->addWidget(m_plot, 1);
    m_result = new QLabel(this);
    m_result->setObjectName("fitResult");
    m_result->setWordWrap(true);
    root->addWidget(m_result);
    auto* buttons = new QDialogButtonBox(this);
    m_fitButton = buttons->addButton(tr("Fit"), QDialogButtonBox::ActionRole);
    m_apply = buttons->addButton(tr("Apply to material"), QDialogButtonBox::AcceptRole);
    buttons->addButton(QDialogButtonBox::Close);
    m_apply->setEnabled(false);
    // Enter runs the fit (never applies a fit made before the file was changed)
    m_fitButton->setDefault(true);
    for (QAbstractButton* b : buttons->buttons())
        if (auto* p = qobject_cast<QPushButton*>(b); p && p != m_fitButton) p->setAutoDefault(false);
    connect(m_file, &QLineEdit::returnPressed, this, [this] { runFit(); });
    connect(m_file, &QLineEdit::textEdited, this, [this] { // a fit of another file is not applied
        m_fitResult.reset();
        m_apply->setEnabled(false);
    });
    root->addWidget(buttons);
    connect(browse, &QPushButton::clicked, this, [this] {
        const QString f = QFileDialog::getOpenFileName(this, tr("Uniaxial test data"), QString(),
                                                       tr("Text and CSV (*.csv *.txt *.dat);;All files (*)"));
        if (!f.isEmpty()) m_file->setText(f);
    });
    connect(m_fitButton, &QPushButton::clicked, this, [this] { runFit(); });
    connect(m_apply, &QPushButton::clicked, this, [this] {
        const QString why = apply();
        if (why.isEmpty())
            accept();
        else
            m_result->setText(why);
    });
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
}

bool FitDialog::runFit() {
    m_fitResult.reset();
    m_apply->setEnabled(false);
    try {
        if (!m_doc->hasProject() || m_body < 0 || m_body >= static_cast<int>(m_doc->project().bodies.size()))
            throw std::invalid_argument("no body selected");
        const sim::Material& m = m_doc->project().bodies[m_body].scene.material;
        const auto start = MaterialPanel::curvesOf(m);
        if (!start) throw std::invalid_argument("the material has no editable curves: apply a preset first");
        m_data = sim::readUniaxialData(m_file->text().toStdString(), m_measure->currentIndex() == 0
                                                                         ? sim::StrainMeasure::Stretch
                                                                         : sim::StrainMeasure::EngineeringStrain);
        sim::FitOptions opt;
        opt.curves = m_curves->currentIndex() == 1 ? sim::FitCurves::FPrimeAndHPrime : sim::FitCurves::FPrime;
        m_fitResult = sim::fitUniaxial(*start, *m_data, opt);
    } catch (const std::exception& e) {
        m_result->setText(QString::fromStdString(e.what()));
        m_plot->setSeries({});
        return false;
    }
    const sim::CurveFitResult& r = *m_fitResult;
    QString text =
        tr("SSE %1 Pa²   R² %2   largest relative error %3 %   data covers stretch %4–%5   "
           "(%6 iterations, %7)")
            .arg(numberText(r.sse, 4),
                 r.rSquared > 0.9999 && r.rSquared < 1 ? QStringLiteral("1 − %1").arg(numberText(1 - r.rSquared, 2))
                                                       : QString::number(r.rSquared, 'f', 6),
                 numberText(100 * r.maxRelativeError, 3), numberText(r.stretchMin, 4), numberText(r.stretchMax, 4))
            .arg(r.iterations)
            .arg(r.converged ? tr("converged") : tr("iteration limit"));
    text += "\n" + changesText(*MaterialPanel::curvesOf(m_doc->project().bodies[m_body].scene.material), r.curves);
    PlotWidget::Series data{tr("test data"), m_data->stretch, m_data->nominalStress, QColor(30, 30, 30), true};
    PlotWidget::Series fit{tr("fitted curves"), {}, {}, QColor(200, 60, 40)};
    const QString unstable = fittedResponse(r, fit);
    if (!unstable.isEmpty()) text += "\n" + tr("Not applied: %1").arg(unstable);
    m_result->setText(text);
    m_result->setStyleSheet(unstable.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
    m_plot->setNote(text.section('\n', 0, 0));
    m_plot->setSeries({fit, data});
    m_apply->setEnabled(unstable.isEmpty());
    return true;
}

QString FitDialog::changesText(const sim::ValanisLandelCurves& before, const sim::ValanisLandelCurves& after) const {
    const sim::SmallStrainConstants a = sim::smallStrainConstants(before), b = sim::smallStrainConstants(after);
    QString t = tr("Small strain: E %1 → %2 Pa, ν %3 → %4")
                    .arg(numberText(a.youngsModulus, 4), numberText(b.youngsModulus, 4), numberText(a.poissonRatio, 3),
                         numberText(b.poissonRatio, 3));
    if (m_curves->currentIndex() == 1) return t + tr(" (f′ and h′ fitted; g′ kept)");
    // f′ alone moves the shear stiffness only: the volume stiffness (Lamé λ, from g′ and h′) stays
    return t + tr(" (h′ and g′ kept: the volume stiffness λ stays %1 Pa, so ν follows the fitted shear "
                  "stiffness; choose \"f′ and h′\" to fit ν to the data)")
                   .arg(numberText(b.lameLambda, 4));
}

QString FitDialog::fittedResponse(const sim::CurveFitResult& r, PlotWidget::Series& fit) const {
    // The fitted material must respond stably wherever the trainee may stretch it: a uniaxial
    // state at every sample and a stress that rises with stretch (Drucker's stability), over
    // the data's range and at least 0.6–1.6.
    try {
        sim::ValanisLandelDensity d("fit", r.curves);
        sim::ResponseSampling s;
        s.stretchMin = std::min(0.6, r.stretchMin);
        s.stretchMax = std::max(1.6, r.stretchMax);
        const sim::ResponseCurves rc = sim::sampleResponses(d, s);
        QString why;
        for (size_t i = 0; i < rc.stretch.size(); ++i) {
            fit.x.push_back(rc.stretch[i]);
            fit.y.push_back(rc.solved[i] ? rc.nominalStress[i] : NAN);
            if (!why.isEmpty()) continue;
            if (!rc.solved[i])
                why = tr("the fitted material has no uniaxial state at stretch %1 (it would be unstable there)")
                          .arg(numberText(rc.stretch[i], 3));
            else if (i > 0 && rc.solved[i - 1] && !(rc.nominalStress[i] > rc.nominalStress[i - 1]))
                why = tr("the fitted material softens at stretch %1 (its stress falls as it is stretched: it would "
                         "be unstable)")
                          .arg(numberText(rc.stretch[i], 3));
        }
        const sim::SmallStrainConstants c = sim::smallStrainConstants(r.curves);
        if (why.isEmpty() && !(c.youngsModulus > 0 && c.poissonRatio >= 0 && c.poissonRatio < 0.5))
            why = tr("the fitted material's small-strain E %1 Pa, ν %2 are outside E > 0, 0 ≤ ν < 0.5")
                      .arg(numberText(c.youngsModulus, 4), numberText(c.poissonRatio, 3));
        return why;
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
}

QString FitDialog::apply() {
    if (!m_fitResult) return tr("nothing fitted yet");
    if (!m_doc->hasProject() || m_body < 0 || m_body >= static_cast<int>(m_doc->project().bodies.size()))
        return tr("no body selected");
    sim::Material m = m_doc->project().bodies[m_body].scene.material;
    sim::setMaterialCurves(m, m_fitResult->curves);
    return m_doc->editMaterial(tr("Fit curves to test data"), m_body, m);
}

} // namespace viscera::studio
