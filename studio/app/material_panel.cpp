#include "app/material_panel.hpp"

#include "app/number_text.hpp"

#include "app/document.hpp"
#include "sim/material/editable_curves.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/material_response.hpp"

#include <QComboBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QSplitter>
#include <QVBoxLayout>

#include <cmath>

namespace viscera::studio {
namespace {

using CurveSlot = std::optional<sim::CurveDesc> sim::Material::*;
constexpr CurveSlot kSlots[3] = {&sim::Material::fPrime, &sim::Material::gPrime, &sim::Material::hPrime};
const char* const kNames[3] = {"f'", "g'", "h'"};
const char* const kTitles[3] = {"f′(λ): one stretch", "g′(λiλj): area", "h′(J): volume"};

std::vector<sim::CurvePoint> toPoints(const sim::CurveDesc& d) {
    std::vector<sim::CurvePoint> p;
    for (const auto& q : d.points)
        p.push_back({q[0], q[1]});
    return p;
}

} // namespace

std::optional<sim::ValanisLandelCurves> MaterialPanel::curvesOf(const sim::Material& m) {
    if (m.model != sim::MaterialModel::ValanisLandel || !m.curvePreset.empty()) return std::nullopt;
    return sim::materialCurves(m, "edited");
}

MaterialPanel::MaterialPanel(Document* doc, QWidget* parent) : QWidget(parent), m_doc(doc) {
    auto* root = new QVBoxLayout(this);
    m_header = new QLabel(this);
    m_header->setWordWrap(true);
    root->addWidget(m_header);

    auto* presetRow = new QHBoxLayout;
    m_law = new QComboBox(this);
    m_law->setObjectName("presetLaw");
    m_law->addItems({"neo_hookean", "st_venant_kirchhoff", "corotated"});
    m_E = new QLineEdit("3000", this);
    m_E->setObjectName("presetE");
    m_nu = new QLineEdit("0.45", this);
    m_nu->setObjectName("presetNu");
    m_applyPreset = new QPushButton(tr("Apply preset"), this);
    m_applyPreset->setObjectName("applyPreset");
    m_fit = new QPushButton(tr("Fit to test data…"), this);
    m_fit->setObjectName("fitButton");
    presetRow->addWidget(new QLabel(tr("Preset"), this));
    presetRow->addWidget(m_law);
    presetRow->addWidget(new QLabel(tr("E [Pa]"), this));
    presetRow->addWidget(m_E);
    presetRow->addWidget(new QLabel(tr("ν"), this));
    presetRow->addWidget(m_nu);
    presetRow->addWidget(m_applyPreset);
    presetRow->addStretch();
    presetRow->addWidget(m_fit);
    root->addLayout(presetRow);

    auto* split = new QSplitter(Qt::Horizontal, this);
    auto* curves = new QSplitter(Qt::Vertical, split);
    for (int k = 0; k < 3; ++k) {
        m_editors[k] = new CurveEditor(curves);
        m_editors[k]->setObjectName(QStringLiteral("curve_%1").arg(k == 0 ? "f" : k == 1 ? "g" : "h"));
        connectEditor(k);
    }
    auto* plots = new QSplitter(Qt::Vertical, split);
    m_uniaxial = new PlotWidget(plots);
    m_uniaxial->setObjectName("uniaxialPlot");
    m_uniaxial->setTitle(tr("Uniaxial tension and compression"));
    m_uniaxial->setAxes(tr("stretch λ"), tr("nominal stress P11 [Pa]"));
    m_shear = new PlotWidget(plots);
    m_shear->setObjectName("shearPlot");
    m_shear->setTitle(tr("Simple shear"));
    m_shear->setAxes(tr("shear γ"), tr("shear stress P12 [Pa]"));
    split->setStretchFactor(0, 3);
    split->setStretchFactor(1, 2);
    root->addWidget(split, 1);

    buildCurveRow(root);
    auto* pointRow = new QHBoxLayout;
    m_x = new QLineEdit(this);
    m_x->setObjectName("pointX");
    m_y = new QLineEdit(this);
    m_y->setObjectName("pointY");
    pointRow->addWidget(new QLabel(tr("Selected point  x"), this));
    pointRow->addWidget(m_x);
    pointRow->addWidget(new QLabel(tr("y [Pa]"), this));
    pointRow->addWidget(m_y);
    root->addLayout(pointRow);
    m_rest = new QLabel(this);
    m_rest->setObjectName("restLabel");
    m_rest->setWordWrap(true);
    // fixed height: its figures change on every drag event, which must not relayout the panel
    m_rest->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
    m_rest->setFixedHeight(2 * m_rest->fontMetrics().lineSpacing() + 4);
    root->addWidget(m_rest);
    m_status = new QLabel(this);
    m_status->setObjectName("materialStatus");
    m_status->setWordWrap(true);
    m_status->setStyleSheet("color: #b00020");
    m_status->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
    m_status->setFixedHeight(2 * m_status->fontMetrics().lineSpacing() + 4);
    root->addWidget(m_status);

    connect(m_x, &QLineEdit::editingFinished, this, [this] { setStatus(applyTypedPoint()); });
    connect(m_y, &QLineEdit::editingFinished, this, [this] { setStatus(applyTypedPoint()); });
    connect(m_applyPreset, &QPushButton::clicked, this, [this] {
        QString why;
        const auto E = parseNumberText(m_E->text(), tr("E"), why);
        const auto nu = E ? parseNumberText(m_nu->text(), tr("ν"), why) : std::nullopt;
        setStatus(nu ? applyPreset(m_law->currentText(), *E, *nu) : why);
    });
    connect(m_fit, &QPushButton::clicked, this, [this] {
        if (m_body >= 0) emit fitRequested(m_body);
    });
    connect(m_doc, &Document::changed, this, [this](const Change& what) {
        if (what.touches(Change::Structure) ||
            (what.touches(Change::Material) && (what.body < 0 || what.body == m_body)))
            refresh();
    });
    refresh();
}

void MaterialPanel::buildCurveRow(QVBoxLayout* root) {
    auto* row = new QHBoxLayout;
    auto button = [&](const QString& text, const char* name, const QString& tip) {
        auto* b = new QPushButton(text, this);
        b->setObjectName(name);
        b->setToolTip(tip);
        row->addWidget(b);
        return b;
    };
    row->addWidget(new QLabel(tr("Whole curve (the one last clicked):"), this));
    QPushButton* scale =
        button(tr("Scale ×"), "scaleCurve",
               tr("Every point's distance from the rest value times the factor: stiffer above 1, softer "
                  "below; the rest point stays"));
    m_scale = new QLineEdit("1.25", this);
    m_scale->setObjectName("scaleFactor");
    m_scale->setMaximumWidth(70);
    row->addWidget(m_scale);
    QPushButton* smooth =
        button(tr("Smooth"), "smoothCurve", tr("Each free point halfway towards the line through its neighbours"));
    QPushButton* reset = button(tr("Reset"), "resetCurve",
                                tr("The curve of the preset law above at the body's E and ν (the other curves stay)"));
    row->addStretch();
    root->addLayout(row);
    connect(scale, &QPushButton::clicked, this, [this] {
        QString why;
        const auto f = parseNumberText(m_scale->text(), tr("scale factor"), why);
        setStatus(f ? scaleCurve(m_active, *f) : why);
    });
    connect(smooth, &QPushButton::clicked, this, [this] { setStatus(smoothCurve(m_active)); });
    connect(reset, &QPushButton::clicked, this, [this] { setStatus(resetCurve(m_active)); });
}

QString MaterialPanel::scaleCurve(int k, double factor) {
    if (!(factor > 0) || !std::isfinite(factor))
        return tr("scale factor %1: must be a positive number (it keeps the curve's order)").arg(numberText(factor));
    return editPoints(k, tr("Scale %1 by %2").arg(kNames[k], numberText(factor)), [&](auto& pts) {
        double rest = NAN;
        for (const auto& p : pts)
            if (p[0] == 1.0) rest = p[1];
        if (!std::isfinite(rest)) throw std::invalid_argument("the curve has no rest point (x = 1) to scale about");
        for (auto& p : pts)
            p[1] = rest + factor * (p[1] - rest);
    });
}

QString MaterialPanel::smoothCurve(int k) {
    return editPoints(k, tr("Smooth %1").arg(kNames[k]), [&](auto& pts) {
        const auto old = pts;
        for (size_t i = 1; i + 1 < pts.size(); ++i) {
            if (old[i][0] == 1.0) continue; // the rest point is pinned
            const double t = (old[i][0] - old[i - 1][0]) / (old[i + 1][0] - old[i - 1][0]);
            const double line = old[i - 1][1] + t * (old[i + 1][1] - old[i - 1][1]);
            pts[i][1] = 0.5 * (old[i][1] + line); // between the neighbours: the order stays
        }
    });
}

QString MaterialPanel::resetCurve(int k) {
    if (m_body < 0 || !m_doc->hasProject() || m_body >= static_cast<int>(m_doc->project().bodies.size()))
        return tr("no body selected");
    sim::Material m = m_doc->project().bodies[m_body].scene.material;
    if (!(m.*kSlots[k])) return tr("the material has no curve %1").arg(kNames[k]);
    sim::Material preset = m;
    try {
        sim::setMaterialCurves(
            preset, sim::editableCurves(m_law->currentText().toStdString(), m.youngsModulus, m.poissonRatio));
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    m.*kSlots[k] = preset.*kSlots[k];
    return m_doc->editMaterial(tr("Reset %1 to %2").arg(kNames[k], m_law->currentText()), m_body, m);
}

void MaterialPanel::setStatus(const QString& error) {
    m_status->setText(error);
}

void MaterialPanel::connectEditor(int k) {
    CurveEditor* e = m_editors[k];
    connect(e, &CurveEditor::selectionChanged, this, [this, k](int) {
        m_active = k;
        showSelected();
    });
    connect(e, &CurveEditor::dragStarted, this, [this, k](int) {
        m_active = k;
        m_dragKey = m_doc->newMergeKey();
    });
    connect(e, &CurveEditor::curveDragged, this, [this, k](int, const std::vector<sim::CurvePoint>& points) {
        setStatus(editPoints(
            k, tr("Move %1 point").arg(kNames[k]),
            [&](auto& pts) {
                if (points.size() != pts.size()) throw std::invalid_argument("the curve changed under the drag");
                for (size_t q = 0; q < pts.size(); ++q)
                    pts[q] = {points[q].x, points[q].y};
            },
            m_dragKey));
    });
    connect(e, &CurveEditor::dragFinished, this, [this](int) { m_dragKey = 0; });
    connect(e, &CurveEditor::insertRequested, this, [this, k](double x, double y) {
        int at = -1;
        const QString why = editPoints(k, tr("Insert %1 point").arg(kNames[k]), [&](auto& pts) {
            auto it = std::lower_bound(pts.begin(), pts.end(), x, [](const auto& p, double v) { return p[0] < v; });
            if (it != pts.end() && (*it)[0] == x) throw std::invalid_argument("a point exists at this stretch");
            at = static_cast<int>(it - pts.begin());
            pts.insert(it, {x, y});
        });
        setStatus(why);
        if (why.isEmpty()) m_editors[k]->setSelected(at);
    });
    connect(e, &CurveEditor::removeRequested, this, [this, k](int i) {
        setStatus(editPoints(k, tr("Delete %1 point").arg(kNames[k]), [&](auto& pts) { pts.erase(pts.begin() + i); }));
    });
}

QString MaterialPanel::editPoints(int k, const QString& text,
                                  const std::function<void(std::vector<std::array<double, 2>>&)>& fn, int mergeKey) {
    if (m_body < 0 || !m_doc->hasProject() || m_body >= static_cast<int>(m_doc->project().bodies.size()))
        return tr("no body selected");
    sim::Material m = m_doc->project().bodies[m_body].scene.material;
    auto& slot = m.*kSlots[k];
    if (!slot) return tr("the material has no curve %1").arg(kNames[k]);
    try {
        fn(slot->points);
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    return m_doc->editMaterial(text, m_body, m, mergeKey);
}

QString MaterialPanel::applyPreset(const QString& law, double E, double nu) {
    if (m_body < 0 || !m_doc->hasProject() || m_body >= static_cast<int>(m_doc->project().bodies.size()))
        return tr("no body selected");
    sim::Material m = m_doc->project().bodies[m_body].scene.material;
    try {
        const sim::ValanisLandelCurves c = sim::editableCurves(law.toStdString(), E, nu);
        sim::setMaterialCurves(m, c);
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    m.youngsModulus = E;
    m.poissonRatio = nu;
    return m_doc->editMaterial(tr("Preset %1").arg(law), m_body, m);
}

QString MaterialPanel::applyTypedPoint() {
    CurveEditor* e = m_editors[m_active];
    const int i = e->selected();
    if (i < 0 || !e->hasCurve()) return {};
    QString why;
    const auto x = parseNumberText(m_x->text(), tr("%1 point %2: x").arg(kNames[m_active]).arg(i), why);
    const auto y =
        x ? parseNumberText(m_y->text(), tr("%1 point %2: y").arg(kNames[m_active]).arg(i), why) : std::nullopt;
    if (!y) return why;
    const sim::CurvePoint& p = e->points()[i];
    if (*x == p.x && *y == p.y) return {};
    if (CurveEditor::isRestPoint(p))
        return tr("%1 point %2 is the rest point (x = 1): pinned, its value keeps the stress at rest zero")
            .arg(kNames[m_active])
            .arg(i);
    const QPointF c = e->constrain(i, QPointF(*x, *y));
    if (c.x() != *x)
        return tr("%1 point %2: x = %3 must lie strictly between its neighbours' x")
            .arg(kNames[m_active])
            .arg(i)
            .arg(numberText(*x));
    if (c.y() != *y)
        return tr("%1 point %2: y = %3 must lie strictly between its neighbours' y (the curve is strictly increasing)")
            .arg(kNames[m_active])
            .arg(i)
            .arg(numberText(*y));
    const int k = m_active;
    return editPoints(k, tr("Set %1 point").arg(kNames[k]), [&](auto& pts) { pts.at(i) = {*x, *y}; });
}

void MaterialPanel::setBody(int index) {
    if (index == m_body) return;
    m_body = index;
    for (CurveEditor* e : m_editors)
        e->setSelected(-1);
    if (m_doc->hasProject() && index >= 0 && index < static_cast<int>(m_doc->project().bodies.size())) {
        // the preset starts from the body's own E and ν
        const sim::Material& m = m_doc->project().bodies[index].scene.material;
        m_E->setText(numberText(m.youngsModulus));
        m_nu->setText(numberText(m.poissonRatio));
    }
    refresh();
    for (CurveEditor* e : m_editors)
        e->frameAll();
}

void MaterialPanel::showSelected() {
    CurveEditor* e = m_editors[m_active];
    const int i = e->selected();
    if (i < 0 || i >= static_cast<int>(e->points().size())) {
        m_x->clear();
        m_y->clear();
        return;
    }
    m_x->setText(numberText(e->points()[i].x, 10));
    m_y->setText(numberText(e->points()[i].y, 10));
}

void MaterialPanel::refresh() {
    const bool have = m_doc->hasProject() && m_body >= 0 && m_body < static_cast<int>(m_doc->project().bodies.size());
    if (!have) {
        m_header->setText(tr("Select a body to edit its material."));
        for (int k = 0; k < 3; ++k)
            m_editors[k]->clearCurve(kTitles[k], tr("no body selected"));
        m_uniaxial->setSeries({});
        m_shear->setSeries({});
        m_rest->clear();
        return;
    }
    const BodyProject& body = m_doc->project().bodies[m_body];
    const sim::Material& m = body.scene.material;
    std::optional<sim::ValanisLandelCurves> curves;
    QString curveError;
    try {
        curves = curvesOf(m);
    } catch (const std::exception& e) {
        curveError = QString::fromStdString(e.what());
        setStatus(curveError);
    }
    m_header->setText(
        curves
            ? tr("Body '%1': Valanis–Landel material, curves edited directly")
                  .arg(QString::fromStdString(body.scene.name))
            : tr("Body '%1': the material has no editable curves (model %2%3). Apply a preset to edit it as a "
                 "Valanis–Landel material.")
                  .arg(QString::fromStdString(body.scene.name), QString::fromStdString(sim::materialModelName(m.model)),
                       m.curvePreset.empty() ? QString()
                                             : tr(", preset %1").arg(QString::fromStdString(m.curvePreset))));
    for (int k = 0; k < 3; ++k) {
        const auto& d = m.*kSlots[k];
        if (curves && d)
            m_editors[k]->setCurve(kTitles[k], toPoints(*d), !d->unconstrained);
        else
            m_editors[k]->clearCurve(kTitles[k], curves ? tr("absent: this term is zero") : tr("no curves"));
    }
    showSelected();
    // the response of the material as the player will simulate it (any model)
    std::unique_ptr<sim::EnergyDensity> density;
    QString restText;
    try {
        if (curves) {
            auto vl = std::make_unique<sim::ValanisLandelDensity>(body.scene.name, *curves);
            const sim::RestNormalization r = sim::restNormalization(*curves);
            const sim::SmallStrainConstants s = sim::smallStrainConstants(*curves);
            restText = tr("Rest normalization (§4.3.3, applied): Ψ(1,1,1) = %1 J/m³, stress at rest f′(1) + 2g′(1) + "
                          "h′(1) = %2 Pa %3.  Small strain: E = %4 Pa, ν = %5, μ = %6 Pa")
                           .arg(numberText(r.restEnergy, 3), numberText(r.restStress, 3),
                                r.balanced ? tr("(zero)") : tr("(NOT ZERO)"), numberText(s.youngsModulus, 4),
                                numberText(s.poissonRatio, 3), numberText(s.shearModulus, 4));
            density = std::move(vl);
        } else if (m.model != sim::MaterialModel::ValanisLandel && m.model != sim::MaterialModel::StableNeoHookean) {
            density = sim::makeEnergyDensity(sim::materialModelName(m.model), m.mu(), m.lambda());
        } else {
            density = sim::makeEnergyDensity("neo_hookean", m.mu(), m.lambda());
            restText = tr("Response shown for the Neo-Hookean law at E = %1 Pa, ν = %2.")
                           .arg(numberText(m.youngsModulus), numberText(m.poissonRatio));
        }
    } catch (const std::exception& e) {
        restText = QString::fromStdString(e.what());
    }
    m_rest->setText(restText);
    if (!density) {
        m_uniaxial->setSeries({});
        m_shear->setSeries({});
        return;
    }
    const sim::ResponseCurves r = sim::sampleResponses(*density);
    PlotWidget::Series uni{tr("P11(λ)"), {}, {}, QColor(200, 60, 40)};
    for (size_t i = 0; i < r.stretch.size(); ++i) {
        uni.x.push_back(r.stretch[i]);
        uni.y.push_back(r.solved[i] ? r.nominalStress[i] : NAN);
    }
    m_uniaxial->setSeries({uni});
    m_shear->setSeries({PlotWidget::Series{tr("P12(γ)"), r.shear, r.shearStress, QColor(40, 90, 200)}});
}

} // namespace viscera::studio
