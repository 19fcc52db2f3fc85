#include "app/assessment_panel.hpp"

#include "app/document.hpp"
#include "app/target_panel.hpp"
#include "sim/scene/assessment.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/json_reader.hpp"

#include <QFileDialog>
#include <QPushButton>

#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QSplitter>
#include <QTableWidget>
#include <QVBoxLayout>

#include <cmath>

namespace viscera::studio {

namespace {

QString number(double v) {
    return QString::number(v, 'g', 6);
}

/// An empty cell is none; otherwise a finite number, or the message saying what was typed.
std::optional<double> parseCell(const QString& text, QString& error) {
    const QString t = text.trimmed();
    if (t.isEmpty()) return std::nullopt;
    bool ok = false;
    const double v = t.toDouble(&ok);
    if (!ok || !std::isfinite(v)) error = QObject::tr("'%1' is not a number (leave the cell empty for none)").arg(t);
    return v;
}

QString targetsText(const std::optional<sim::AssessmentDesc>& a) {
    if (!a) return QObject::tr("No assessment: sessions of this case get figures, not a verdict.");
    QStringList parts;
    for (const sim::CutTarget& c : a->cuts)
        parts << QObject::tr("open %1 % of a %2-point line (within %3 mm)")
                     .arg(c.coverage * 100, 0, 'g', 3)
                     .arg(c.line.size())
                     .arg(c.radius * 1e3, 0, 'g', 3);
    for (const sim::ClipTarget& c : a->clips)
        parts << QObject::tr("%1 clip(s) within %2 mm of a site").arg(c.count).arg(c.tolerance * 1e3, 0, 'g', 3);
    if (a->suture)
        parts << QObject::tr("%1 bites across the wound, gap ≤ %2 mm")
                     .arg(a->suture->bites)
                     .arg(a->suture->maxGap * 1e3, 0, 'g', 3);
    return parts.isEmpty() ? QObject::tr("Targets: none (the completion time is not measured).")
                           : QObject::tr("Targets: ") + parts.join("; ") + ".";
}

} // namespace

AssessmentPanel::AssessmentPanel(Document* doc, TargetTool* targets, QWidget* parent) : QWidget(parent), m_doc(doc) {
    auto* layout = new QVBoxLayout(this);
    m_targets = new QLabel(this);
    m_targets->setObjectName("assessmentTargets");
    m_targets->setWordWrap(true);
    layout->addWidget(m_targets);
    // the targets above the metrics, the split between them the artist's to move
    auto* split = new QSplitter(Qt::Vertical, this);
    split->setObjectName("assessmentSplit");
    split->setChildrenCollapsible(false);
    if (targets) {
        m_targetPanel = new TargetPanel(doc, targets, split);
        split->addWidget(m_targetPanel);
    }
    auto* row = new QHBoxLayout;
    row->addWidget(new QLabel(tr("Force threshold (N):"), this));
    m_threshold = new QLineEdit(this);
    m_threshold->setObjectName("force_threshold_n");
    row->addWidget(m_threshold);
    auto* import = new QPushButton(tr("Import expert levels…"), this);
    import->setObjectName("importExpertLevels");
    import->setToolTip(tr("Expert means and SDs from viscera-results expert-levels (the experts' sessions)"));
    row->addWidget(import);
    connect(import, &QPushButton::clicked, this, [this] {
        const QString path = QFileDialog::getOpenFileName(this, tr("Expert levels"), {}, tr("JSON (*.json)"));
        if (!path.isEmpty()) importExpertLevels(path);
    });
    const auto& metrics = sim::metricCatalogue();
    m_table = new QTableWidget(static_cast<int>(metrics.size()), Columns, this);
    m_table->setObjectName("assessmentTable");
    m_table->setHorizontalHeaderLabels(
        {tr("Metric"), tr("Unit"), tr("Better"), tr("Limit"), tr("Expert mean"), tr("Expert SD")});
    m_table->verticalHeader()->hide();
    m_table->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    for (int r = 0; r < static_cast<int>(metrics.size()); ++r) {
        const sim::MetricInfo& m = metrics[static_cast<size_t>(r)];
        const QString tip = QString::fromUtf8(m.definition.data(), static_cast<int>(m.definition.size()));
        const QString cells[] = {QString::fromUtf8(m.name.data(), static_cast<int>(m.name.size())),
                                 QString::fromUtf8(m.unit.data(), static_cast<int>(m.unit.size())),
                                 m.lowerIsBetter ? tr("lower") : tr("higher")};
        for (int c = 0; c < 3; ++c) {
            auto* item = new QTableWidgetItem(cells[c]);
            item->setFlags(item->flags() & ~Qt::ItemIsEditable);
            item->setToolTip(tip);
            m_table->setItem(r, c, item);
        }
        for (int c = Limit; c < Columns; ++c)
            m_table->setItem(r, c, new QTableWidgetItem);
    }
    auto* metricsBox = new QWidget(split);
    auto* metricsLayout = new QVBoxLayout(metricsBox);
    metricsLayout->setContentsMargins(0, 0, 0, 0);
    metricsLayout->addLayout(row);
    metricsLayout->addWidget(m_table, 1);
    split->addWidget(metricsBox);
    layout->addWidget(split, 1);
    m_error = new QLabel(this);
    m_error->setObjectName("assessmentError");
    m_error->setWordWrap(true);
    m_error->setStyleSheet("color: #b00");
    layout->addWidget(m_error);
    connect(m_table, &QTableWidget::cellChanged, this, &AssessmentPanel::cellTyped);
    connect(m_threshold, &QLineEdit::editingFinished, this, &AssessmentPanel::thresholdTyped);
    connect(m_doc, &Document::changed, this, [this](const Change&) { fill(); });
    fill();
}

void AssessmentPanel::fill() {
    m_filling = true;
    const Project* p = (m_doc->hasProject() ? &m_doc->project() : nullptr);
    const std::optional<sim::AssessmentDesc> a = p ? p->scene.assessment : std::nullopt;
    m_targets->setText(targetsText(a));
    m_threshold->setText(a ? number(a->forceThresholdN) : QString());
    m_threshold->setEnabled(a.has_value());
    for (int r = 0; r < m_table->rowCount(); ++r) {
        const sim::MetricLevel* l = a ? a->level(m_table->item(r, Metric)->text().toStdString()) : nullptr;
        m_table->item(r, Limit)->setText(l && l->limit ? number(*l->limit) : QString());
        m_table->item(r, ExpertMean)->setText(l && l->expert ? number(l->expert->mean) : QString());
        m_table->item(r, ExpertSd)->setText(l && l->expert ? number(l->expert->sd) : QString());
    }
    m_filling = false;
}

void AssessmentPanel::cellTyped(int row, int column) {
    if (m_filling || column < Limit || !(m_doc->hasProject() ? &m_doc->project() : nullptr)) return;
    QString error;
    auto cell = [&](int c) { return parseCell(m_table->item(row, c)->text(), error); };
    const std::optional<double> limit = cell(Limit), mean = cell(ExpertMean), sd = cell(ExpertSd);
    const std::string name = m_table->item(row, Metric)->text().toStdString();
    if (error.isEmpty() && mean.has_value() != sd.has_value())
        error = tr("%1: an expert level needs both a mean and an SD").arg(QString::fromStdString(name));
    if (!error.isEmpty()) {
        if (mean.has_value() != sd.has_value() && column != Limit) { // half an expert level: wait for the other
            m_error->setText(error);
            return;
        }
        apply(error);
        return;
    }
    sim::AssessmentDesc a =
        (m_doc->hasProject() ? &m_doc->project() : nullptr)->scene.assessment.value_or(sim::AssessmentDesc{});
    std::vector<sim::MetricLevel> levels;
    for (const sim::MetricInfo& info : sim::metricCatalogue()) { // catalogue order, this row replaced
        if (info.name == name) {
            if (limit || mean)
                levels.push_back({name, limit, mean ? std::optional(sim::ExpertLevel{*mean, *sd}) : std::nullopt});
        } else if (const sim::MetricLevel* l = a.level(info.name)) {
            levels.push_back(*l);
        }
    }
    a.metrics = std::move(levels);
    apply(m_doc->editAssessment(tr("Assessment: %1").arg(QString::fromStdString(name)), a));
}

void AssessmentPanel::thresholdTyped() {
    const Project* p = (m_doc->hasProject() ? &m_doc->project() : nullptr);
    if (m_filling || !p || !p->scene.assessment) return;
    QString error;
    const std::optional<double> v = parseCell(m_threshold->text(), error);
    if (!error.isEmpty() || !v) return apply(error.isEmpty() ? tr("the force threshold needs a value") : error);
    if (*v == p->scene.assessment->forceThresholdN) return;
    sim::AssessmentDesc a = *p->scene.assessment;
    a.forceThresholdN = *v;
    apply(m_doc->editAssessment(tr("Assessment: force threshold"), a));
}

QString AssessmentPanel::importExpertLevels(const QString& path) {
    if (!m_doc->hasProject()) return tr("no project is open");
    sim::AssessmentDesc a = m_doc->project().scene.assessment.value_or(sim::AssessmentDesc{});
    int n = 0;
    try {
        const std::string file = path.toStdString();
        const nlohmann::json doc = sim::parseJsonText(readFile(file), file);
        const sim::JsonField root(doc, "", file);
        root.object({"case_id", "experts", "sessions", "metrics"});
        const sim::JsonField c = root["case_id"];
        if (c.string() != m_doc->project().caseId)
            c.fail("'" + c.string() + "' is not this project's case ('" + m_doc->project().caseId + "')");
        const auto members = root["metrics"].members();
        if (members.empty()) root.failAt("metrics", "has no expert level");
        for (const auto& [name, m] : members) {
            if (!sim::findMetric(name)) m.fail("is not a metric the player measures");
            m.object({"expert", "n"});
            m["n"].integer(2, 1000000); // sessions behind the level: a mean and an SD need two
            const sim::JsonField e = m["expert"];
            e.object({"mean", "sd"});
            const sim::ExpertLevel level{e["mean"].number(sim::NumberRule::nonNegative()),
                                         e["sd"].number(sim::NumberRule::nonNegative())};
            std::vector<sim::MetricLevel> levels;
            bool found = false;
            for (const sim::MetricInfo& info : sim::metricCatalogue()) // catalogue order
                if (info.name == name) {
                    const sim::MetricLevel* old = a.level(name);
                    levels.push_back({name, old ? old->limit : std::nullopt, level});
                    found = true;
                } else if (const sim::MetricLevel* l = a.level(info.name)) {
                    levels.push_back(*l);
                }
            if (found) a.metrics = std::move(levels), ++n;
        }
    } catch (const std::exception& e) {
        m_error->setText(QString::fromStdString(e.what()));
        return m_error->text();
    }
    const QString why = m_doc->editAssessment(tr("Import %1 expert levels").arg(n), a);
    apply(why);
    return why;
}

void AssessmentPanel::apply(const QString& why) {
    m_error->setText(why);
    if (!why.isEmpty()) fill(); // the model's values again
}

} // namespace viscera::studio
