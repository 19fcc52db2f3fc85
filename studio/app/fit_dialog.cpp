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
    setWindowTitle(tr("Fit material curves to test data"));
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
    // a second test of the same material pins what one uniaxial test leaves free (ν)
    auto* secondRow = new QHBoxLayout;
    m_secondFile = new QLineEdit(this);
    m_secondFile->setObjectName("fitSecondFile");
    m_secondFile->setPlaceholderText(tr("optional: a second test of the same material"));
    m_secondCase = new QComboBox(this);
    m_secondCase->setObjectName("fitSecondCase");
    m_secondCase->addItems({tr("equibiaxial"), tr("planar shear")});
    auto* browse2 = new QPushButton(tr("Browse…"), this);
    secondRow->addWidget(m_secondFile, 1);
    secondRow->addWidget(m_secondCase);
    secondRow->addWidget(browse2);
    form->addRow(tr("Second test"), secondRow);
    connect(browse2, &QPushButton::clicked, this, [this] {
        const QString f = QFileDialog::getOpenFileName(this, tr("Equibiaxial or planar shear test data"), QString(),
                                                       tr("Text and CSV (*.csv *.txt *.dat);;All files (*)"));
        if (!f.isEmpty()) m_secondFile->setText(f);
    });
    m_curves = new QComboBox(this);
    m_curves->setObjectName("fitCurves");
    // f′ alone by default: a uniaxial test fixes one function of stretch, and f′ carries it; ν
    // stays where the artist put it (h′ follows the fitted shear stiffness) unless the artist
    // asks for it to be fitted too
    m_curves->addItems({tr("f′ only (the stretch response; ν kept)"), tr("f′ and h′ (ν fitted too)")});
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
    // a fit of other data or other settings is never applied (Browse sets the text too)
    auto drop = [this] {
        m_fitResult.reset();
        m_apply->setEnabled(false);
    };
    for (QLineEdit* f : {m_file, m_secondFile})
        connect(f, &QLineEdit::textChanged, this, drop);
    for (QComboBox* c : {m_measure, m_curves, m_secondCase})
        connect(c, &QComboBox::currentIndexChanged, this, drop);
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
        m_data = readData();
        sim::FitOptions opt;
        opt.curves = m_curves->currentIndex() == 1 ? sim::FitCurves::FPrimeAndHPrime
                     : keepsPoisson(*start)        ? sim::FitCurves::FPrimeKeepingPoisson
                                                   : sim::FitCurves::FPrime;
        m_fitResult = bestFit(*start, *m_data, opt);
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
    if (!m_startNote.isEmpty()) text += "\n" + m_startNote;
    PlotWidget::Series fit{tr("fitted curves"), {}, {}, QColor(200, 60, 40)};
    const QString unstable = fittedResponse(r, fit);
    if (!unstable.isEmpty()) text += "\n" + tr("Not applied: %1").arg(unstable);
    m_result->setText(text);
    m_result->setStyleSheet(unstable.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
    m_plot->setNote(text.section('\n', 0, 0));
    std::vector<PlotWidget::Series> series{fit};
    secondTestSeries(r, series);
    m_plot->setSeries(std::move(series));
    m_apply->setEnabled(unstable.isEmpty());
    return true;
}

sim::UniaxialData FitDialog::readData() const {
    const auto measure =
        m_measure->currentIndex() == 0 ? sim::StrainMeasure::Stretch : sim::StrainMeasure::EngineeringStrain;
    sim::UniaxialData uni = sim::readUniaxialData(m_file->text().toStdString(), measure);
    if (m_secondFile->text().trimmed().isEmpty()) return uni;
    const sim::UniaxialData second = sim::readUniaxialData(m_secondFile->text().trimmed().toStdString(), measure);
    return sim::combineTests({{sim::LoadCase::Uniaxial, uni}, {secondCase(), second}});
}

sim::LoadCase FitDialog::secondCase() const {
    return m_secondCase->currentIndex() == 0 ? sim::LoadCase::Equibiaxial : sim::LoadCase::PlanarShear;
}

sim::CurveFitResult FitDialog::bestFit(const sim::ValanisLandelCurves& start, const sim::UniaxialData& data,
                                       const sim::FitOptions& opt) {
    m_startNote.clear();
    if (data.loadCase.empty() || opt.curves != sim::FitCurves::FPrimeAndHPrime)
        return sim::fitUniaxial(start, data, opt);
    std::optional<sim::CurveFitResult> best;
    std::string firstError;
    try {
        best = sim::fitUniaxial(start, data, opt);
    } catch (const std::exception& e) { // the material's curves may have no state in the second test
        firstError = e.what();
    }
    // Two tests and h′ free: the fit is local and the start's ν decides where it ends; the
    // Neo-Hookean curves at the material's small-strain E and several ν are tried too, the
    // smallest SSE kept.
    const double E0 = sim::smallStrainConstants(start).youngsModulus;
    QString won = tr("the material's curves");
    for (const double E : {0.5 * E0, E0, 2 * E0})
        for (const double nu : {0.3, 0.4, 0.45, 0.49}) {
            try {
                sim::CurveFitResult r = sim::fitUniaxial(sim::editableCurves("neo_hookean", E, nu), data, opt);
                if (!best || r.sse < best->sse) {
                    best = std::move(r);
                    won = tr("the Neo-Hookean curves at E %1 Pa, ν %2").arg(numberText(E, 4), numberText(nu, 3));
                }
            } catch (const std::exception&) { // a start without a state at some data stretch: not a candidate
            }
        }
    m_startNote = tr("Two tests: fitted from the material's curves and from Neo-Hookean curves at ½, 1 and 2 times "
                     "its E and ν 0.3–0.49; the best started from %1.")
                      .arg(won);
    if (!best) throw std::invalid_argument(firstError); // no start had a state at every data stretch
    return *best;
}

void FitDialog::secondTestSeries(const sim::CurveFitResult& r, std::vector<PlotWidget::Series>& series) const {
    const sim::UniaxialData& d = *m_data;
    PlotWidget::Series uni{tr("uniaxial data"), {}, {}, QColor(30, 30, 30), true};
    PlotWidget::Series other{tr("%1 data").arg(sim::loadCaseName(secondCase())), {}, {}, QColor(30, 120, 60), true};
    for (size_t i = 0; i < d.size(); ++i) {
        const bool second = !d.loadCase.empty() && d.loadCase[i] != sim::LoadCase::Uniaxial;
        (second ? other : uni).x.push_back(d.stretch[i]);
        (second ? other : uni).y.push_back(d.nominalStress[i]);
    }
    series.push_back(uni);
    if (other.x.empty()) return;
    // the fitted material in the second test, over that test's range
    PlotWidget::Series fit{tr("fitted, %1").arg(sim::loadCaseName(secondCase())), {}, {}, QColor(60, 160, 90)};
    try {
        const sim::ValanisLandelDensity density("fit", r.curves);
        const auto [lo, hi] = std::minmax_element(other.x.begin(), other.x.end());
        for (int k = 0; k <= 60; ++k) {
            const double s = *lo + (*hi - *lo) * k / 60.0;
            const sim::UniaxialResponse u = sim::solveLoadCase(density, secondCase(), s);
            fit.x.push_back(s);
            fit.y.push_back(u.solved ? u.nominalStress : NAN);
        }
    } catch (const std::exception&) {
    }
    series.push_back(fit);
    series.push_back(other);
}

bool FitDialog::keepsPoisson(const sim::ValanisLandelCurves& curves) {
    return curves.hPrime && curves.hPrime->derivative(1.0) > 0;
}

QString FitDialog::changesText(const sim::ValanisLandelCurves& before, const sim::ValanisLandelCurves& after) const {
    const sim::SmallStrainConstants a = sim::smallStrainConstants(before), b = sim::smallStrainConstants(after);
    QString t = tr("Small strain: E %1 → %2 Pa, ν %3 → %4")
                    .arg(numberText(a.youngsModulus, 4), numberText(b.youngsModulus, 4), numberText(a.poissonRatio, 3),
                         numberText(b.poissonRatio, 3));
    if (m_curves->currentIndex() == 1) return t + tr(" (f′ and h′ fitted; g′ kept)");
    if (keepsPoisson(before))
        return t + tr(" (ν kept: h′ scaled with the fitted shear stiffness, g′ kept; choose \"f′ and h′\" to fit "
                      "ν to the data)");
    // no h′ to scale: the volume stiffness (Lamé λ, from g′) stays and ν follows the shear stiffness
    return t + tr(" (this material has no h′ to keep ν with: g′ kept, the volume stiffness λ stays %1 Pa, so ν "
                  "follows the fitted shear stiffness; apply the Neo-Hookean preset to keep ν)")
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
