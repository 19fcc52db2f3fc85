#include "app/rehearse_panel.hpp"

#include "app/document.hpp"
#include "app/rehearsal.hpp"
#include "app/viewport.hpp"
#include "haptics/scripted_device.hpp"
#include "runtime/keyboard_keys.hpp"

#include <QComboBox>
#include <QDir>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QMouseEvent>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSpinBox>
#include <QVBoxLayout>
#include <QWheelEvent>
#include <QWidget>
#include <QWindow>

namespace viscera::studio {

RehearsePanel::RehearsePanel(Document* doc, QWidget* parent)
    : QWidget(parent), m_doc(doc), m_rehearsal(new Rehearsal(this)) {
    auto* form = new QFormLayout;
    m_device = new QComboBox(this);
    m_device->setObjectName("rehearseDevice");
    m_device->setEditable(true); // any player --device spec; the list holds the usual ones
    // a long replay path must not widen the dock (and shrink the viewport)
    m_device->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
    m_device->setMinimumContentsLength(20);
    m_device->setToolTip(tr("A player --device spec: keyboard, replay:<file.csv>, scripted:<name>, "
                            "console:<host:port>"));
    form->addRow(tr("Device"), m_device);
    m_pairingKey = new QLineEdit(this);
    m_pairingKey->setObjectName("rehearsePairingKey");
    m_pairingKey->setPlaceholderText(tr("console only: the pairing key file"));
    form->addRow(tr("Pairing key"), m_pairingKey);
    m_frames = new QSpinBox(this);
    m_frames->setObjectName("rehearseFrames");
    m_frames->setRange(0, 1'000'000);
    m_frames->setSpecialValueText(tr("auto"));
    m_frames->setToolTip(tr("auto: a replay's length, 300 frames for a script, until Stop for the "
                            "keyboard and the console"));
    form->addRow(tr("Frames"), m_frames);

    m_start = new QPushButton(tr("Rehearse"), this);
    m_start->setObjectName("rehearseStart");
    m_stop = new QPushButton(tr("Stop"), this);
    m_stop->setObjectName("rehearseStop");
    auto* buttons = new QHBoxLayout;
    buttons->addWidget(m_start);
    buttons->addWidget(m_stop);

    m_status = new QLabel(tr("Runs the case as the player does, from the model as it is now."), this);
    m_status->setObjectName("rehearseStatus");
    m_status->setWordWrap(true);
    m_verdict = new QLabel(this);
    m_verdict->setObjectName("rehearseVerdict");
    m_verdict->setWordWrap(true);
    QFont big = m_verdict->font();
    big.setPointSizeF(big.pointSizeF() * 1.4);
    big.setBold(true);
    m_verdict->setFont(big);
    m_summary = new QPlainTextEdit(this);
    m_summary->setObjectName("rehearseSummary");
    m_summary->setReadOnly(true);
    m_summary->setLineWrapMode(QPlainTextEdit::NoWrap);
    m_summary->setMinimumHeight(140);

    m_name = new QLineEdit(QStringLiteral("rehearsal"), this);
    m_name->setObjectName("rehearseReplayName");
    m_keep = new QPushButton(tr("Keep as reference replay"), this);
    m_keep->setObjectName("rehearseKeep");
    m_keep->setToolTip(tr("Writes the session's device as replays/<name>.csv of the project and replays "
                          "it in lockstep: the verdict the player gives that replay"));
    auto* keepRow = new QHBoxLayout;
    keepRow->addWidget(m_name, 1);
    keepRow->addWidget(m_keep);

    auto* col = new QVBoxLayout(this);
    col->addLayout(form);
    col->addLayout(buttons);
    col->addWidget(m_status);
    col->addWidget(m_verdict);
    col->addWidget(m_summary, 1);
    col->addWidget(new QLabel(tr("Reference replay name"), this));
    col->addLayout(keepRow);

    connect(m_start, &QPushButton::clicked, this, [this] { start(); });
    connect(m_stop, &QPushButton::clicked, m_rehearsal, &Rehearsal::stop);
    connect(m_keep, &QPushButton::clicked, this, [this] { keep(); });
    connect(m_rehearsal, &Rehearsal::progress, m_status, &QLabel::setText);
    connect(m_rehearsal, &Rehearsal::started, this, [this] {
        m_dragging = false;
        if (m_viewport) {
            m_viewport->setRestPose(-1); // every mesh as the session moves it (a paint tool may have held one)
            m_viewport->setFocus();
        }
        showScene();
    });
    connect(m_rehearsal, &Rehearsal::frame, this, &RehearsePanel::showScene);
    connect(m_rehearsal, &Rehearsal::finished, this, &RehearsePanel::onFinished);
    connect(m_rehearsal, &Rehearsal::stateChanged, this, [this](Rehearsal::State s) {
        syncButtons();
        if (s == Rehearsal::State::Exporting) emit activeChanged(true);
    });
    refreshDevices();
    syncButtons();
}

RehearsePanel::~RehearsePanel() {
    if (m_canvas) m_canvas->removeEventFilter(this);
}

void RehearsePanel::refreshDevices() {
    const QString current = m_device->currentText();
    m_device->clear();
    m_device->addItem(QStringLiteral("keyboard"));
    if (m_doc->hasProject()) {
        const QDir replays(QString::fromStdString((m_doc->project().dir / "replays").string()));
        for (const QString& f : replays.entryList({"*.csv"}, QDir::Files, QDir::Name))
            m_device->addItem(QStringLiteral("replay:") + replays.filePath(f));
    }
    for (const std::string& s : haptics::ScriptedDevice::scripts())
        m_device->addItem(QStringLiteral("scripted:") + QString::fromStdString(s));
    m_device->addItem(QStringLiteral("console:127.0.0.1:7400"));
    if (!current.isEmpty()) m_device->setCurrentText(current);
}

void RehearsePanel::connectViewport(Viewport* v) {
    if (m_canvas) m_canvas->removeEventFilter(this);
    m_viewport = v;
    m_canvas = nullptr;
    if (!v) return;
    m_canvas = v->canvasWindow() ? static_cast<QObject*>(v->canvasWindow()) : v->canvasWidget();
    if (m_canvas) m_canvas->installEventFilter(this);
    if (m_rehearsal->live()) showScene();
}

bool RehearsePanel::start() {
    if (!m_doc->hasProject()) {
        emit refused(tr("rehearse: open or create a project first"));
        return false;
    }
    Rehearsal::Options o;
    o.device = m_device->currentText();
    o.frames = m_frames->value();
    o.pairingKey = m_pairingKey->text().trimmed();
    QString why;
    m_verdict->clear();
    m_summary->clear();
    if (!m_rehearsal->start(m_doc->project(), o, &why)) {
        m_status->setText(why);
        emit refused(tr("rehearse: %1").arg(why));
        return false;
    }
    return true;
}

bool RehearsePanel::keep() {
    if (!m_doc->hasProject() || m_rehearsal->active()) return false;
    QString why;
    const QString path = m_rehearsal->keepReplay(m_doc->project().dir, m_name->text().trimmed(), &why);
    if (path.isEmpty()) {
        m_status->setText(why);
        emit refused(tr("keep replay: %1").arg(why));
        return false;
    }
    refreshDevices();
    m_device->setCurrentText(QStringLiteral("replay:") + path);
    m_frames->setValue(0);
    m_replayingKept = start();
    m_status->setText(tr("kept %1; replaying it as the player would").arg(path));
    return true;
}

void RehearsePanel::showScene() {
    const player::LiveScene* live = m_rehearsal->live();
    if (m_viewport && live) m_viewport->setScene(live->view());
}

void RehearsePanel::onFinished(bool ok) {
    const Rehearsal::Outcome& o = m_rehearsal->outcome();
    const bool kept = std::exchange(m_replayingKept, false);
    if (!o.ran) {
        m_verdict->setText(tr("Not run"));
        m_verdict->setStyleSheet("color: #b02020;");
        m_summary->setPlainText(o.error);
    } else {
        const QString who = kept ? tr("The kept replay: ") : QString();
        m_verdict->setText(who + (o.judged ? o.verdict : tr("no assessment in this case")));
        m_verdict->setStyleSheet(!ok || (o.judged && !o.passed) ? "color: #b02020;" : "color: #1a7f2a;");
        QString text = tr("%1 frames with %2; physics %3 ms per frame (real time: %4 ms)\n")
                           .arg(o.frames)
                           .arg(o.device)
                           .arg(o.physicsMs, 0, 'f', 2)
                           .arg(o.frameDt * 1e3, 0, 'f', 1);
        if (!o.error.isEmpty()) text += tr("error: %1\n").arg(o.error);
        m_summary->setPlainText(text + o.summary.join('\n'));
    }
    syncButtons();
    emit activeChanged(false);
}

void RehearsePanel::syncButtons() {
    const bool active = m_rehearsal->active();
    m_start->setEnabled(!active);
    m_stop->setEnabled(active);
    m_keep->setEnabled(!active && m_rehearsal->recorded().arms() > 0);
    m_device->setEnabled(!active);
    m_frames->setEnabled(!active);
}

bool RehearsePanel::eventFilter(QObject* watched, QEvent* event) {
    if (watched == m_canvas && m_rehearsal->keyboard() && keyboardEvent(event)) return true;
    return QWidget::eventFilter(watched, event);
}

bool RehearsePanel::keyboardEvent(QEvent* event) {
    haptics::KeyboardDevice* kb = m_rehearsal->keyboard();
    switch (event->type()) {
    case QEvent::KeyPress:
    case QEvent::KeyRelease: {
        auto* e = static_cast<QKeyEvent*>(event);
        const auto k = player::keyboardKey(e->key());
        if (!k) return false;
        if (!e->isAutoRepeat()) kb->setKey(*k, event->type() == QEvent::KeyPress);
        return true;
    }
    case QEvent::MouseButtonPress: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (e->button() != Qt::LeftButton || (e->modifiers() & Qt::AltModifier)) return false;
        m_mouse = e->position().toPoint();
        m_dragging = true;
        return true;
    }
    case QEvent::MouseMove: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (!m_dragging) return false;
        const QPoint p = e->position().toPoint();
        kb->addMouse(p.x() - m_mouse.x(), p.y() - m_mouse.y(), 0);
        m_mouse = p;
        return true;
    }
    case QEvent::MouseButtonRelease:
        if (!m_dragging) return false;
        m_dragging = false;
        return true;
    case QEvent::FocusOut:
    case QEvent::WindowDeactivate:
    case QEvent::Hide: {
        // the releases would go elsewhere: nothing stays held, no drag carries on
        for (uint32_t k = haptics::KeyboardDevice::KeyLeft; k & haptics::KeyboardDevice::kAllKeys; k <<= 1)
            kb->setKey(static_cast<haptics::KeyboardDevice::Key>(k), false);
        m_dragging = false;
        return false;
    }
    case QEvent::Wheel: {
        auto* e = static_cast<QWheelEvent*>(event);
        if (e->modifiers() & Qt::AltModifier) return false;
        kb->addMouse(0, 0, e->angleDelta().y() / 120.0);
        return true;
    }
    default:
        return false;
    }
}

} // namespace viscera::studio
