#include "app/scope_task_panel.hpp"

#include "app/document.hpp"
#include "app/number_text.hpp"
#include "app/viewport.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QVBoxLayout>

#include <algorithm>
#include <array>

namespace viscera::studio {
namespace {

/// A number field of the scope: its key (object name), label, and place in the description.
struct ScopeNumber {
    const char* key;
    const char* label;
    double& (*of)(sim::LaparoscopeDesc&);
};

const std::array<ScopeNumber, 12>& scopeNumbers() {
    static const std::array<ScopeNumber, 12> n = {{
        {"port_x", "Port x (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.port.position.x(); }},
        {"port_y", "Port y (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.port.position.y(); }},
        {"port_z", "Port z (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.port.position.z(); }},
        {"insertion_min", "Insertion min (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.port.insertionMin; }},
        {"insertion_max", "Insertion max (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.port.insertionMax; }},
        {"max_angle_deg", "Max angle (°)", [](sim::LaparoscopeDesc& d) -> double& { return d.port.maxAngleDeg; }},
        {"shaft_length", "Shaft length (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.port.shaftLength; }},
        {"fov_deg", "Field of view (°)", [](sim::LaparoscopeDesc& d) -> double& { return d.fovDeg; }},
        {"motion_scale", "Motion scale", [](sim::LaparoscopeDesc& d) -> double& { return d.motionScale; }},
        {"tip_x", "Tip x (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.tip.x(); }},
        {"tip_y", "Tip y (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.tip.y(); }},
        {"tip_z", "Tip z (m)", [](sim::LaparoscopeDesc& d) -> double& { return d.tip.z(); }},
    }};
    return n;
}

const char* const kHands[] = {"left", "right", "any"};

} // namespace

std::optional<sim::Vec3> scopeTipFromView(const sim::PortDesc& port, const sim::Vec3& eye, const sim::Vec3& target,
                                          QString& why) {
    const sim::Vec3 toTarget = target - port.position;
    if (!toTarget.allFinite() || toTarget.norm() < 1e-3) {
        why = QObject::tr("laparoscope.tip: the camera looks at the port itself; look past it into the body");
        return std::nullopt;
    }
    const sim::Vec3 d = toTarget.normalized();
    const double depth = std::clamp((eye - port.position).dot(d), port.insertionMin, port.insertionMax);
    return sim::Vec3(port.position + depth * d);
}

ScopeTaskPanel::ScopeTaskPanel(Document* doc, std::function<const Viewport*()> viewport, QWidget* parent)
    : QWidget(parent), m_doc(doc), m_viewport(std::move(viewport)) {
    auto* layout = new QVBoxLayout(this);
    buildScope();
    buildTask();
    m_error = new QLabel(this);
    m_error->setObjectName("scopeTaskError");
    m_error->setWordWrap(true);
    m_error->setStyleSheet("color: #b00");
    layout->addWidget(m_error);
    layout->addStretch(1);
    connect(m_doc, &Document::changed, this, [this](const Change&) { fill(); });
    fill();
}

void ScopeTaskPanel::buildScope() {
    auto* box = new QGroupBox(tr("Laparoscope"), this);
    auto* column = new QVBoxLayout(box);
    m_present = new QCheckBox(tr("Case has a laparoscope"), box);
    m_present->setObjectName("scopePresent");
    column->addWidget(m_present);
    m_scopeFields = new QWidget(box);
    auto* form = new QFormLayout(m_scopeFields);
    form->setContentsMargins(0, 0, 0, 0);
    for (const ScopeNumber& n : scopeNumbers()) {
        auto* f = new QLineEdit(m_scopeFields);
        f->setObjectName(n.key);
        form->addRow(tr(n.label), f);
        const QString key = n.key;
        connect(f, &QLineEdit::editingFinished, this, [this, key] { numberTyped(key); });
        if (key == "shaft_length") { // the choices after the port's numbers
            m_optic = new QComboBox(m_scopeFields);
            m_optic->setObjectName("optic");
            m_optic->addItem(tr("0° (forward-viewing)"), 0.0);
            m_optic->addItem(tr("30°"), 30.0);
            form->addRow(tr("Optic"), m_optic);
        }
    }
    m_hand = new QComboBox(m_scopeFields);
    m_hand->setObjectName("hand");
    for (const char* h : kHands)
        m_hand->addItem(h);
    form->addRow(tr("Steered by"), m_hand);
    column->addWidget(m_scopeFields);
    m_setView = new QPushButton(tr("Set scope view from here"), box);
    m_setView->setObjectName("setScopeView");
    m_setView->setToolTip(tr("The scope's rest tip from the viewport's camera: the shaft from the port towards "
                             "where the camera looks, as deep as the camera's eye (within the insertion range)"));
    column->addWidget(m_setView);
    layout()->addWidget(box);
    connect(m_present, &QCheckBox::toggled, this, &ScopeTaskPanel::presentToggled);
    connect(m_optic, &QComboBox::activated, this, [this] { choiceChanged(); });
    connect(m_hand, &QComboBox::activated, this, [this] { choiceChanged(); });
    connect(m_setView, &QPushButton::clicked, this, [this] { setScopeViewFromCamera(); });
}

void ScopeTaskPanel::buildTask() {
    auto* box = new QGroupBox(tr("Task"), this);
    auto* form = new QFormLayout(box);
    m_title = new QLineEdit(box);
    m_title->setObjectName("taskTitle");
    form->addRow(tr("Title"), m_title);
    m_instructions = new QLineEdit(box);
    m_instructions->setObjectName("taskInstructions");
    m_instructions->setToolTip(tr("One line of printable text, shown under the title"));
    form->addRow(tr("Instructions"), m_instructions);
    m_steps = new QListWidget(box);
    m_steps->setObjectName("taskSteps");
    m_steps->setMinimumHeight(60);
    m_steps->setMaximumHeight(140);
    form->addRow(tr("Steps"), m_steps);
    auto* buttons = new QHBoxLayout;
    auto button = [&](const QString& text, const char* name) {
        auto* b = new QPushButton(text, box);
        b->setObjectName(name);
        buttons->addWidget(b);
        return b;
    };
    m_addStep = button(tr("Add"), "addStep");
    m_removeStep = button(tr("Remove"), "removeStep");
    m_stepUp = button(tr("Up"), "stepUp");
    m_stepDown = button(tr("Down"), "stepDown");
    form->addRow(QString(), buttons);
    layout()->addWidget(box);
    connect(m_title, &QLineEdit::editingFinished, this, &ScopeTaskPanel::taskTyped);
    connect(m_instructions, &QLineEdit::editingFinished, this, &ScopeTaskPanel::taskTyped);
    // queued: the edit refills the list, which must not happen inside the item's own setData
    connect(
        m_steps, &QListWidget::itemChanged, this,
        [this] {
            if (!m_filling) taskTyped();
        },
        Qt::QueuedConnection);
    connect(m_addStep, &QPushButton::clicked, this, [this] {
        // a new, empty step in the list only: it enters the model when typed (an empty step is none)
        auto* item = new QListWidgetItem(m_steps);
        item->setFlags(item->flags() | Qt::ItemIsEditable);
        m_steps->setCurrentItem(item);
        m_steps->editItem(item);
    });
    connect(m_removeStep, &QPushButton::clicked, this, [this] {
        if (QListWidgetItem* item = m_steps->currentItem()) {
            delete item;
            taskTyped();
        }
    });
    connect(m_stepUp, &QPushButton::clicked, this, [this] { moveStep(-1); });
    connect(m_stepDown, &QPushButton::clicked, this, [this] { moveStep(1); });
}

QLineEdit* ScopeTaskPanel::field(const QString& key) const {
    return m_scopeFields->findChild<QLineEdit*>(key);
}

void ScopeTaskPanel::fill() {
    m_filling = true;
    const Project* p = m_doc->hasProject() ? &m_doc->project() : nullptr;
    const std::optional<sim::LaparoscopeDesc> scope = p ? p->scene.laparoscope : std::nullopt;
    setEnabled(p != nullptr);
    m_present->setChecked(scope.has_value());
    m_scopeFields->setEnabled(scope.has_value());
    m_setView->setEnabled(scope.has_value());
    sim::LaparoscopeDesc d = scope.value_or(sim::LaparoscopeDesc{});
    for (const ScopeNumber& n : scopeNumbers())
        field(n.key)->setText(scope ? numberText(n.of(d)) : QString());
    m_optic->setCurrentIndex(d.opticDeg == 0 ? 0 : 1);
    m_hand->setCurrentIndex(std::max(0, m_hand->findText(QString::fromStdString(d.hand))));
    m_title->setText(p ? QString::fromStdString(p->title) : QString());
    m_instructions->setText(p ? QString::fromStdString(p->scene.instructions) : QString());
    m_steps->clear();
    if (p)
        for (const std::string& s : p->scene.steps) {
            auto* item = new QListWidgetItem(QString::fromStdString(s), m_steps);
            item->setFlags(item->flags() | Qt::ItemIsEditable);
        }
    m_filling = false;
}

void ScopeTaskPanel::apply(const QString& why) {
    m_error->setText(why);
    if (!why.isEmpty()) fill(); // the fields show the model again
}

void ScopeTaskPanel::editScope(const sim::LaparoscopeDesc& next, const QString& what) {
    apply(m_doc->editLaparoscope(tr("Laparoscope: %1").arg(what), next));
}

void ScopeTaskPanel::numberTyped(const QString& key) {
    if (m_filling || !m_doc->hasProject() || !m_doc->project().scene.laparoscope) return;
    sim::LaparoscopeDesc next = *m_doc->project().scene.laparoscope;
    for (const ScopeNumber& n : scopeNumbers()) {
        if (key != n.key) continue;
        if (field(key)->text().trimmed() == numberText(n.of(next))) return; // focus left an unchanged field
        QString why;
        const std::optional<double> v = parseNumberText(field(key)->text(), tr("laparoscope: %1").arg(key), why);
        if (!v) return apply(why);
        n.of(next) = *v;
        return editScope(next, tr(n.label));
    }
}

void ScopeTaskPanel::presentToggled(bool on) {
    if (m_filling || !m_doc->hasProject()) return;
    if (!on) return apply(m_doc->editLaparoscope(tr("Remove the laparoscope"), std::nullopt));
    sim::LaparoscopeDesc d;
    const Viewport* v = viewport();
    const sim::Vec3 target = v ? sim::Vec3(v->cameraTarget().cast<double>()) : sim::Vec3(sim::Vec3::Zero());
    d.port.declared = true;
    d.port.mode = sim::PortMode::Robotic; // what the scene reader makes of a scope's port
    d.port.position = target + sim::Vec3(0, 0, 0.15);
    d.tip = d.port.position + sim::Vec3(0, 0, -0.08);
    apply(m_doc->editLaparoscope(tr("Add a laparoscope"), d));
}

void ScopeTaskPanel::choiceChanged() {
    if (m_filling || !m_doc->hasProject() || !m_doc->project().scene.laparoscope) return;
    sim::LaparoscopeDesc next = *m_doc->project().scene.laparoscope;
    next.opticDeg = m_optic->currentData().toDouble();
    next.hand = m_hand->currentText().toStdString();
    const sim::LaparoscopeDesc& now = *m_doc->project().scene.laparoscope;
    if (next.opticDeg == now.opticDeg && next.hand == now.hand) return;
    editScope(next, next.opticDeg != now.opticDeg ? tr("optic") : tr("hand"));
}

QString ScopeTaskPanel::setScopeViewFromCamera() {
    const Viewport* v = viewport();
    if (!v || !m_doc->hasProject() || !m_doc->project().scene.laparoscope) {
        const QString why = tr("laparoscope: the case has none (check \"Case has a laparoscope\" first)");
        apply(why);
        return why;
    }
    sim::LaparoscopeDesc next = *m_doc->project().scene.laparoscope;
    const render::Camera& c = v->camera();
    QString why;
    const std::optional<sim::Vec3> tip =
        scopeTipFromView(next.port, c.position.cast<double>(), c.target.cast<double>(), why);
    if (!tip) {
        apply(why);
        return why;
    }
    next.tip = *tip;
    why = m_doc->editLaparoscope(tr("Set scope view from here"), next);
    apply(why);
    return why;
}

void ScopeTaskPanel::taskTyped() {
    if (m_filling || !m_doc->hasProject()) return;
    std::vector<std::string> steps;
    for (int k = 0; k < m_steps->count(); ++k)
        if (const QString s = m_steps->item(k)->text(); !s.isEmpty()) steps.push_back(s.toStdString());
    const Project& p = m_doc->project();
    const std::string title = m_title->text().toStdString(), instructions = m_instructions->text().toStdString();
    if (title == p.title && instructions == p.scene.instructions && steps == p.scene.steps) return;
    apply(m_doc->editTask(tr("Task"), title, instructions, steps));
}

void ScopeTaskPanel::moveStep(int by) {
    const int row = m_steps->currentRow(), to = row + by;
    if (row < 0 || to < 0 || to >= m_steps->count()) return;
    m_filling = true;
    QListWidgetItem* item = m_steps->takeItem(row);
    m_steps->insertItem(to, item);
    m_filling = false;
    taskTyped();
    m_steps->setCurrentRow(to);
}

} // namespace viscera::studio
