#include "app/target_panel.hpp"

#include "app/document.hpp"
#include "app/number_text.hpp"
#include "app/target_tool.hpp"

#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QTableWidget>
#include <QToolButton>
#include <QVBoxLayout>

#include <cmath>

namespace viscera::studio {

namespace {

using Row = TargetPanel::Row;
using Kind = Row::Kind;
using sim::AssessmentDesc;

QString millimetres(const sim::Vec3& p) {
    return QString("%1, %2, %3").arg(p.x() * 1e3, 0, 'f', 1).arg(p.y() * 1e3, 0, 'f', 1).arg(p.z() * 1e3, 0, 'f', 1);
}

/// A row whose value is a number shown and typed in `scale` units (1e3: mm, 100: %).
Row numberRow(QString target, QString field, Kind kind, int index, double scale,
              std::function<double*(AssessmentDesc&)> ref) {
    Row r{std::move(target), std::move(field), kind, index, {}, {}};
    r.text = [ref, scale](const AssessmentDesc& a) {
        AssessmentDesc copy = a;
        const double* v = ref(copy);
        return v ? numberText(*v * scale) : QString();
    };
    r.set = [ref, scale](AssessmentDesc& a, const QString& typed) {
        bool ok = false;
        const double v = typed.trimmed().toDouble(&ok);
        if (!ok || !std::isfinite(v)) return QObject::tr("'%1' is not a number").arg(typed.trimmed());
        if (double* to = ref(a)) *to = v / scale;
        return QString();
    };
    return r;
}

/// A row whose value is a whole number.
Row countRow(QString target, QString field, Kind kind, int index, std::function<int*(AssessmentDesc&)> ref) {
    Row r{std::move(target), std::move(field), kind, index, {}, {}};
    r.text = [ref](const AssessmentDesc& a) {
        AssessmentDesc copy = a;
        const int* v = ref(copy);
        return v ? QString::number(*v) : QString();
    };
    r.set = [ref](AssessmentDesc& a, const QString& typed) {
        bool ok = false;
        const int v = typed.trimmed().toInt(&ok);
        if (!ok) return QObject::tr("'%1' is not a whole number").arg(typed.trimmed());
        if (int* to = ref(a)) *to = v;
        return QString();
    };
    return r;
}

Row textRow(QString target, QString field, Kind kind, int index, std::function<QString(const AssessmentDesc&)> text) {
    return Row{std::move(target), std::move(field), kind, index, std::move(text), {}};
}

void cutRows(const AssessmentDesc& a, std::vector<Row>& rows) {
    for (size_t i = 0; i < a.cuts.size(); ++i) {
        const QString t = QObject::tr("cut %1").arg(i + 1);
        const int k = static_cast<int>(i);
        rows.push_back(textRow(t, QObject::tr("line"), Kind::Cut, k, [i](const AssessmentDesc& d) {
            double length = 0;
            for (size_t j = 1; j < d.cuts[i].line.size(); ++j)
                length += (d.cuts[i].line[j] - d.cuts[i].line[j - 1]).norm();
            return QObject::tr("%1 points, %2 mm long").arg(d.cuts[i].line.size()).arg(length * 1e3, 0, 'f', 1);
        }));
        auto cut = [i](AssessmentDesc& d) { return i < d.cuts.size() ? &d.cuts[i] : nullptr; };
        rows.push_back(numberRow(t, QObject::tr("radius (mm)"), Kind::Cut, k, 1e3, [cut](AssessmentDesc& d) {
            auto* c = cut(d);
            return c ? &c->radius : nullptr;
        }));
        rows.push_back(numberRow(t, QObject::tr("coverage (%)"), Kind::Cut, k, 100, [cut](AssessmentDesc& d) {
            auto* c = cut(d);
            return c ? &c->coverage : nullptr;
        }));
    }
}

void clipRows(const AssessmentDesc& a, std::vector<Row>& rows) {
    for (size_t i = 0; i < a.clips.size(); ++i) {
        const QString t = QObject::tr("clip %1").arg(i + 1);
        const int k = static_cast<int>(i);
        rows.push_back(textRow(t, QObject::tr("position (mm)"), Kind::Clip, k,
                               [i](const AssessmentDesc& d) { return millimetres(d.clips[i].position); }));
        auto clip = [i](AssessmentDesc& d) { return i < d.clips.size() ? &d.clips[i] : nullptr; };
        rows.push_back(numberRow(t, QObject::tr("tolerance (mm)"), Kind::Clip, k, 1e3, [clip](AssessmentDesc& d) {
            auto* c = clip(d);
            return c ? &c->tolerance : nullptr;
        }));
        rows.push_back(countRow(t, QObject::tr("count"), Kind::Clip, k, [clip](AssessmentDesc& d) {
            auto* c = clip(d);
            return c ? &c->count : nullptr;
        }));
    }
}

void sutureRows(const AssessmentDesc& a, std::vector<Row>& rows) {
    if (!a.suture) return;
    const QString t = QObject::tr("suture");
    rows.push_back(textRow(t, QObject::tr("plane (mm)"), Kind::Suture, 0, [](const AssessmentDesc& d) {
        const sim::Vec3& n = d.suture->planeNormal;
        return QObject::tr("at %1, normal %2, %3, %4")
            .arg(millimetres(d.suture->planePoint))
            .arg(n.x(), 0, 'f', 2)
            .arg(n.y(), 0, 'f', 2)
            .arg(n.z(), 0, 'f', 2);
    }));
    rows.push_back(countRow(t, QObject::tr("bites"), Kind::Suture, 0,
                            [](AssessmentDesc& d) { return d.suture ? &d.suture->bites : nullptr; }));
    const std::pair<QString, double sim::SutureTarget::*> fields[] = {
        {QObject::tr("depth min (mm)"), &sim::SutureTarget::depthMin},
        {QObject::tr("depth max (mm)"), &sim::SutureTarget::depthMax},
        {QObject::tr("spacing min (mm)"), &sim::SutureTarget::spacingMin},
        {QObject::tr("spacing max (mm)"), &sim::SutureTarget::spacingMax},
        {QObject::tr("max gap (mm)"), &sim::SutureTarget::maxGap}};
    for (const auto& [field, member] : fields)
        rows.push_back(numberRow(t, field, Kind::Suture, 0, 1e3,
                                 [member](AssessmentDesc& d) { return d.suture ? &(*d.suture.*member) : nullptr; }));
}

void vesselRows(const AssessmentDesc& a, std::vector<Row>& rows) {
    if (!a.vessel) return;
    const QString t = QObject::tr("vessel");
    Row body = textRow(t, QObject::tr("body"), Kind::Vessel, 0,
                       [](const AssessmentDesc& d) { return QString::fromStdString(d.vessel->body); });
    body.set = [](AssessmentDesc& d, const QString& typed) {
        if (!d.vessel) return QObject::tr("there is no vessel to protect");
        d.vessel->body = typed.trimmed().toStdString();
        return QString();
    };
    rows.push_back(std::move(body));
    rows.push_back(numberRow(t, QObject::tr("margin (mm)"), Kind::Vessel, 0, 1e3,
                             [](AssessmentDesc& d) { return d.vessel ? &d.vessel->margin : nullptr; }));
}

} // namespace

TargetPanel::TargetPanel(Document* doc, TargetTool* tool, QWidget* parent) : QWidget(parent), m_doc(doc) {
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    auto* tools = new QHBoxLayout;
    for (auto pick : {TargetTool::Pick::CutLine, TargetTool::Pick::ClipSite, TargetTool::Pick::SuturePlane,
                      TargetTool::Pick::Vessel}) {
        auto* b = new QToolButton(this);
        b->setDefaultAction(tool->action(pick));
        b->setObjectName(tool->action(pick)->objectName() + "Button");
        tools->addWidget(b);
    }
    m_remove = new QPushButton(tr("Remove target"), this);
    m_remove->setObjectName("removeTarget");
    m_remove->setToolTip(tr("Takes out the target of the selected row"));
    tools->addWidget(m_remove);
    tools->addStretch(1);
    layout->addLayout(tools);
    m_table = new QTableWidget(0, Columns, this);
    m_table->setObjectName("targetTable");
    m_table->setHorizontalHeaderLabels({tr("Target"), tr("Field"), tr("Value")});
    m_table->verticalHeader()->hide();
    m_table->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    m_table->horizontalHeader()->setStretchLastSection(true);
    m_table->setSelectionBehavior(QAbstractItemView::SelectRows);
    layout->addWidget(m_table, 1);
    m_error = new QLabel(this);
    m_error->setObjectName("targetError");
    m_error->setWordWrap(true);
    m_error->setStyleSheet("color: #b00");
    layout->addWidget(m_error);
    connect(m_table, &QTableWidget::cellChanged, this, &TargetPanel::typed);
    connect(m_remove, &QPushButton::clicked, this, [this] { removeTargetOf(m_table->currentRow()); });
    connect(tool, &TargetTool::refused, this, [this](const QString& why) { m_error->setText(why); });
    connect(m_doc, &Document::changed, this, [this](const Change&) { fill(); });
    fill();
}

std::optional<sim::AssessmentDesc> TargetPanel::model() const {
    return m_doc->hasProject() ? m_doc->project().scene.assessment : std::nullopt;
}

void TargetPanel::fill() {
    m_filling = true;
    const AssessmentDesc a = model().value_or(AssessmentDesc{});
    m_rows.clear();
    cutRows(a, m_rows);
    clipRows(a, m_rows);
    sutureRows(a, m_rows);
    vesselRows(a, m_rows);
    m_table->setRowCount(static_cast<int>(m_rows.size()));
    for (int r = 0; r < static_cast<int>(m_rows.size()); ++r) {
        const Row& row = m_rows[static_cast<size_t>(r)];
        const QString cells[] = {row.target, row.field, row.text(a)};
        for (int c = 0; c < Columns; ++c) {
            // the items stay (one may be the cell being committed): text and flags are set anew
            QTableWidgetItem* item = m_table->item(r, c);
            if (!item) {
                item = new QTableWidgetItem;
                m_table->setItem(r, c, item);
            }
            const bool editable = c == Value && row.set;
            item->setText(cells[c]);
            item->setFlags(editable ? item->flags() | Qt::ItemIsEditable : item->flags() & ~Qt::ItemIsEditable);
            item->setForeground(
                palette().color(c == Value && !editable ? QPalette::Disabled : QPalette::Active, QPalette::Text));
        }
    }
    m_remove->setEnabled(!m_rows.empty());
    m_filling = false;
}

int TargetPanel::row(const QString& target, const QString& field) const {
    for (size_t r = 0; r < m_rows.size(); ++r)
        if (m_rows[r].target == target && m_rows[r].field == field) return static_cast<int>(r);
    return -1;
}

void TargetPanel::typed(int r, int column) {
    if (m_filling || column != Value || r < 0 || r >= static_cast<int>(m_rows.size()) || !model()) return;
    const Row& row = m_rows[static_cast<size_t>(r)];
    if (!row.set) return fill();
    AssessmentDesc a = *model();
    const QString error = row.set(a, m_table->item(r, Value)->text());
    if (!error.isEmpty()) return show(tr("%1: %2: %3").arg(row.target, row.field, error));
    show(m_doc->editAssessment(tr("Target %1: %2").arg(row.target, row.field), a));
}

QString TargetPanel::removeTargetOf(int r) {
    if (r < 0 || r >= static_cast<int>(m_rows.size()) || !model()) return tr("no target is selected");
    const Row row = m_rows[static_cast<size_t>(r)];
    AssessmentDesc a = *model();
    const auto in = [&](const auto& v) { return row.index >= 0 && row.index < static_cast<int>(v.size()); };
    if ((row.kind == Kind::Cut && !in(a.cuts)) || (row.kind == Kind::Clip && !in(a.clips)))
        return tr("no target is selected");
    switch (row.kind) {
    case Kind::Cut:
        a.cuts.erase(a.cuts.begin() + row.index);
        break;
    case Kind::Clip:
        a.clips.erase(a.clips.begin() + row.index);
        break;
    case Kind::Suture:
        a.suture.reset();
        break;
    case Kind::Vessel:
        a.vessel.reset();
        break;
    }
    const QString why = m_doc->editAssessment(tr("Remove target %1").arg(row.target), a);
    show(why);
    return why;
}

void TargetPanel::show(const QString& why) {
    m_error->setText(why);
    if (!why.isEmpty()) fill(); // the model's values again
}

} // namespace viscera::studio
