#include "app/instrument_panel.hpp"

#include "app/document.hpp"
#include "app/number_text.hpp"
#include "sim/scene/interaction.hpp"

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
#include <optional>

namespace viscera::studio {
namespace {

using Kind = sim::InstrumentDesc::Kind;

enum Group { Tool, Master, Port };

/// A number field of an instrument: its key, label, JSON path (below the instrument), group and
/// place in the description.
struct InstrumentNumber {
    const char* key;
    const char* label;
    const char* path;
    Group group;
    double& (*of)(sim::InstrumentDesc&);
};

using In = sim::InstrumentDesc;
const std::array<InstrumentNumber, 13>& instrumentNumbers() {
    static const std::array<InstrumentNumber, 13> n = {{
        {"temperature_c", "Temperature (°C)", "temperature_c", Tool, [](In& d) -> double& { return d.temperatureC; }},
        {"radius", "Radius (m)", "radius", Tool, [](In& d) -> double& { return d.radius; }},
        {"jaw_length", "Jaw length (m)", "jaw_length", Tool, [](In& d) -> double& { return d.jawLength; }},
        {"motion_scale", "Motion scale", "device.motion_scale", Master,
         [](In& d) -> double& { return d.device.motionScale; }},
        {"force_scale", "Force scale", "device.force_scale", Master,
         [](In& d) -> double& { return d.device.forceScale; }},
        {"max_force_n", "Max force (N)", "device.max_force_n", Master,
         [](In& d) -> double& { return d.device.maxForceN; }},
        {"port_x", "Position x (m)", "port.position[0]", Port, [](In& d) -> double& { return d.port.position.x(); }},
        {"port_y", "Position y (m)", "port.position[1]", Port, [](In& d) -> double& { return d.port.position.y(); }},
        {"port_z", "Position z (m)", "port.position[2]", Port, [](In& d) -> double& { return d.port.position.z(); }},
        {"insertion_min", "Insertion min (m)", "port.insertion[0]", Port,
         [](In& d) -> double& { return d.port.insertionMin; }},
        {"insertion_max", "Insertion max (m)", "port.insertion[1]", Port,
         [](In& d) -> double& { return d.port.insertionMax; }},
        {"max_angle_deg", "Max angle (°)", "port.max_angle_deg", Port,
         [](In& d) -> double& { return d.port.maxAngleDeg; }},
        {"shaft_length", "Shaft length (m)", "port.shaft_length", Port,
         [](In& d) -> double& { return d.port.shaftLength; }},
    }};
    return n;
}

const InstrumentNumber* findNumber(const QString& key) {
    for (const InstrumentNumber& n : instrumentNumbers())
        if (key == n.key) return &n;
    return nullptr;
}

const char* const kHands[] = {"left", "right", "any"};

QString kindLabel(Kind k) {
    return instrumentKindLabel(k);
}

const sim::InstrumentDesc* instrumentAt(const Document* doc, int i) {
    if (!doc->hasProject() || !doc->project().scene.interaction || i < 0) return nullptr;
    const auto& list = doc->project().scene.interaction->instruments;
    return i < static_cast<int>(list.size()) ? &list[static_cast<size_t>(i)] : nullptr;
}

} // namespace

QString instrumentKindLabel(sim::InstrumentDesc::Kind k) {
    switch (k) {
    case Kind::Grasper:
        return QObject::tr("grasper");
    case Kind::EnergyHook:
        return QObject::tr("energy hook");
    case Kind::ClipApplier:
        return QObject::tr("clip applier");
    case Kind::Scissors:
        return QObject::tr("scissors");
    case Kind::NeedleDriver:
        return QObject::tr("needle driver");
    }
    return {};
}

InstrumentPanel::InstrumentPanel(Document* doc, QWidget* parent) : QWidget(parent), m_doc(doc) {
    auto* layout = new QVBoxLayout(this);
    m_list = new QListWidget(this);
    m_list->setObjectName("instrumentList");
    m_list->setMinimumHeight(60);
    m_list->setMaximumHeight(120);
    layout->addWidget(m_list);
    auto* row = new QHBoxLayout;
    m_addKind = new QComboBox(this);
    m_addKind->setObjectName("instrumentAddKind");
    for (Kind k : {Kind::Grasper, Kind::EnergyHook, Kind::ClipApplier, Kind::Scissors, Kind::NeedleDriver})
        m_addKind->addItem(kindLabel(k), static_cast<int>(k));
    m_addKind->setToolTip(tr("The kind Add makes: a grasper on the left master, the others on the right"));
    row->addWidget(m_addKind, 1);
    m_add = new QPushButton(tr("Add"), this);
    m_add->setObjectName("instrumentAdd");
    row->addWidget(m_add);
    m_remove = new QPushButton(tr("Remove"), this);
    m_remove->setObjectName("instrumentRemove");
    row->addWidget(m_remove);
    layout->addLayout(row);
    m_fields = new QWidget(this);
    auto* fieldsLayout = new QVBoxLayout(m_fields);
    fieldsLayout->setContentsMargins(0, 0, 0, 0);
    m_form = new QFormLayout;
    buildFields(m_form);
    fieldsLayout->addLayout(m_form);
    layout->addWidget(m_fields);
    m_error = new QLabel(this);
    m_error->setObjectName("instrumentError");
    m_error->setWordWrap(true);
    m_error->setStyleSheet("color: #b00");
    layout->addWidget(m_error);
    layout->addStretch(1);
    connect(m_list, &QListWidget::currentRowChanged, this, [this](int r) {
        if (m_filling) return;
        m_selected = r;
        fillFields();
        emit selectedChanged(m_selected);
    });
    connect(m_add, &QPushButton::clicked, this, &InstrumentPanel::addClicked);
    connect(m_remove, &QPushButton::clicked, this, &InstrumentPanel::removeClicked);
    connect(m_doc, &Document::changed, this, [this](const Change&) { fill(); });
    fill();
}

QLineEdit* InstrumentPanel::addField(QFormLayout* form, const QString& key, const QString& label, const QString& tip) {
    auto* f = new QLineEdit(m_fields);
    f->setObjectName("instrument_" + key);
    f->setToolTip(tip);
    form->addRow(label, f);
    connect(f, &QLineEdit::editingFinished, this, [this, key] { fieldTyped(key); });
    return f;
}

void InstrumentPanel::buildFields(QFormLayout* form) {
    // one form in three parts (a heading row each): the tool, its master, its port
    auto heading = [&](const QString& text) {
        auto* l = new QLabel("<b>" + text + "</b>", m_fields);
        form->addRow(l);
    };
    heading(tr("Tool"));
    addField(form, "name", tr("Name"), tr("Names the instrument and its track in the case"));
    m_target = new QComboBox(m_fields);
    m_target->setObjectName("instrument_target");
    m_target->setToolTip(tr("The tet body (vessel) the clip applier clips"));
    form->addRow(tr("Clips"), m_target);
    Group group = Tool;
    for (const InstrumentNumber& n : instrumentNumbers()) {
        if (n.group != group) {
            group = n.group;
            if (group == Master) {
                heading(tr("Master"));
                m_hand = new QComboBox(m_fields);
                m_hand->setObjectName("instrument_hand");
                for (const char* h : kHands)
                    m_hand->addItem(h);
                form->addRow(tr("Hand"), m_hand);
            } else {
                heading(tr("Port"));
            }
        }
        addField(form, n.key, tr(n.label), QString(n.path));
        if (QString(n.key) == "max_force_n")
            addField(form, "damage_force_n", tr("Damage threshold (N)"),
                     tr("Contact force above which tissue is damaged; empty: the assessment's force threshold"));
    }
    m_mode = new QComboBox(m_fields);
    m_mode->setObjectName("instrument_mode");
    m_mode->addItem(tr("laparoscopic"), static_cast<int>(sim::PortMode::Laparoscopic));
    m_mode->addItem(tr("robotic"), static_cast<int>(sim::PortMode::Robotic));
    form->addRow(tr("Mode"), m_mode);
    for (QComboBox* c : {m_target, m_hand, m_mode})
        connect(c, &QComboBox::activated, this, [this] { choiceMade(); });
}

QLineEdit* InstrumentPanel::field(const QString& key) const {
    if (key != "name" && key != "damage_force_n" && !findNumber(key)) return nullptr;
    return m_fields->findChild<QLineEdit*>("instrument_" + key);
}

void InstrumentPanel::fill() {
    m_filling = true;
    m_list->clear();
    const std::vector<sim::InstrumentDesc> none;
    const auto& list = m_doc->hasProject() && m_doc->project().scene.interaction
                           ? m_doc->project().scene.interaction->instruments
                           : none;
    for (const sim::InstrumentDesc& in : list)
        m_list->addItem(QStringLiteral("%1 — %2 — %3")
                            .arg(QString::fromStdString(in.name), kindLabel(in.kind),
                                 in.device.declared ? QString::fromStdString(in.device.hand) : tr("scripted")));
    const int before = m_selected;
    m_selected = list.empty() ? -1 : std::clamp(m_selected, 0, static_cast<int>(list.size()) - 1);
    m_list->setCurrentRow(m_selected);
    m_filling = false;
    fillFields();
    if (m_selected != before) emit selectedChanged(m_selected);
}

void InstrumentPanel::fillFields() {
    m_filling = true;
    const sim::InstrumentDesc* in = instrumentAt(m_doc, m_selected);
    m_fields->setEnabled(in != nullptr);
    m_remove->setEnabled(in != nullptr);
    m_add->setEnabled(m_doc->hasProject());
    sim::InstrumentDesc shown = in ? *in : sim::InstrumentDesc{};
    field("name")->setText(in ? QString::fromStdString(in->name) : QString());
    for (const InstrumentNumber& n : instrumentNumbers())
        field(n.key)->setText(in ? numberText(n.of(shown)) : QString());
    field("damage_force_n")->setText(in && in->device.damageForceN ? numberText(*in->device.damageForceN) : QString());
    m_target->clear();
    if (m_doc->hasProject())
        for (const BodyProject& b : m_doc->project().bodies)
            m_target->addItem(QString::fromStdString(b.scene.name));
    m_target->setCurrentIndex(m_target->findText(QString::fromStdString(shown.target)));
    m_hand->setCurrentIndex(m_hand->findText(QString::fromStdString(shown.device.hand)));
    m_mode->setCurrentIndex(m_mode->findData(static_cast<int>(shown.port.mode)));
    // the kind's own fields only
    m_form->setRowVisible(m_target, shown.kind == Kind::ClipApplier);
    m_form->setRowVisible(field("temperature_c"), shown.kind == Kind::EnergyHook);
    m_filling = false;
}

void InstrumentPanel::addClicked() {
    if (!m_doc->hasProject()) return;
    const auto kind = static_cast<Kind>(m_addKind->currentData().toInt());
    const std::string hand = kind == Kind::Grasper ? "left" : "right";
    const int before = m_doc->project().scene.interaction
                           ? static_cast<int>(m_doc->project().scene.interaction->instruments.size())
                           : 0;
    m_selected = before; // the new one, once the model has it
    const QString why = m_doc->addInstrument(tr("Add a %1").arg(kindLabel(kind)), kind, hand);
    if (!why.isEmpty()) m_selected = std::max(0, before - 1);
    apply(why);
}

void InstrumentPanel::removeClicked() {
    const sim::InstrumentDesc* in = instrumentAt(m_doc, m_selected);
    if (!in) return;
    apply(m_doc->removeInstrument(tr("Remove %1").arg(QString::fromStdString(in->name)), m_selected));
}

void InstrumentPanel::fieldTyped(const QString& key) {
    const sim::InstrumentDesc* in = instrumentAt(m_doc, m_selected);
    if (m_filling || !in) return;
    sim::InstrumentDesc next = *in;
    const QString text = field(key)->text().trimmed();
    const QString path = QStringLiteral("interaction.instruments[%1].").arg(m_selected);
    QString why;
    if (key == "name") {
        if (text.toStdString() == in->name) return;
        next.name = text.toStdString();
        return editSelected(next, tr("name"));
    }
    if (key == "damage_force_n") { // empty: none
        std::optional<double> v;
        if (!text.isEmpty() && !(v = parseNumberText(text, path + "device.damage_force_n", why))) return apply(why);
        if (v == in->device.damageForceN) return;
        next.device.damageForceN = v;
        next.device.declared = true;
        return editSelected(next, tr("damage threshold"));
    }
    const InstrumentNumber* n = findNumber(key);
    const std::optional<double> v = parseNumberText(text, path + n->path, why);
    if (!v) return apply(why);
    double& slot = n->of(next);
    if (slot == *v) return;
    slot = *v;
    next.device.declared |= n->group == Master;
    next.port.declared |= n->group == Port;
    editSelected(next, tr(n->label));
}

void InstrumentPanel::choiceMade() {
    const sim::InstrumentDesc* in = instrumentAt(m_doc, m_selected);
    if (m_filling || !in) return;
    sim::InstrumentDesc next = *in;
    if (in->kind == Kind::ClipApplier && m_target->currentIndex() >= 0)
        next.target = m_target->currentText().toStdString();
    const std::string hand = m_hand->currentText().toStdString();
    const auto mode = static_cast<sim::PortMode>(m_mode->currentData().toInt());
    QString what = tr("target");
    if (hand != in->device.hand || (!in->device.declared && hand != sim::DeviceMapping{}.hand)) {
        next.device.hand = hand;
        next.device.declared = true;
        what = tr("hand");
    }
    if (mode != in->port.mode) {
        next.port.mode = mode;
        next.port.declared = true;
        what = tr("port mode");
    }
    if (next.target == in->target && next.device.hand == in->device.hand && next.port.mode == in->port.mode &&
        next.device.declared == in->device.declared)
        return;
    editSelected(next, what);
}

void InstrumentPanel::editSelected(const sim::InstrumentDesc& next, const QString& what) {
    const sim::InstrumentDesc* in = instrumentAt(m_doc, m_selected);
    if (!in) return;
    apply(m_doc->editInstrument(tr("Instrument %1: %2").arg(QString::fromStdString(in->name), what), m_selected, next));
}

void InstrumentPanel::apply(const QString& why) {
    m_error->setText(why);
    if (!why.isEmpty()) fill(); // the model's values again
}

} // namespace viscera::studio
