#include "picker_window.hpp"

#include <QFont>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QPointer>

#include <algorithm>

namespace viscera::launcher {
namespace {

constexpr int kMargin = 32;
constexpr int kTilesTop = 176; ///< below the header and the trainee row
constexpr int kFooter = 104;   ///< the status line and the Start button
constexpr int kTileHeight = 150;
constexpr int kGap = 16;
constexpr int kMinTileWidth = 460;

const QColor kBackground(24, 26, 30);
const QColor kText(235, 235, 235);
const QColor kDim(170, 176, 184);
const QColor kAccent(90, 200, 120);
const QColor kError(235, 110, 100);

QFont font(int pixels, bool bold) {
    QFont f;
    f.setPixelSize(pixels);
    f.setBold(bold);
    return f;
}

QString q(const std::string& s) {
    return QString::fromStdString(s);
}

} // namespace

PickerWindow::PickerWindow(PickerContent content, LaunchSettings settings, Launch launch)
    : m_content(std::move(content)), m_settings(std::move(settings)), m_launch(std::move(launch)) {
    setTitle("Viscera — choose a case");
    resize(1280, 800);
    if (!m_content.cases.empty()) m_selected = 0;
}

int PickerWindow::columns(QSize size) const {
    return std::max(1, (size.width() - 2 * kMargin + kGap) / (kMinTileWidth + kGap));
}

int PickerWindow::visibleRows(QSize size) const {
    return std::max(1, (size.height() - kTilesTop - kFooter + kGap) / (kTileHeight + kGap));
}

QRect PickerWindow::tileRect(int index, QSize size) const {
    const int cols = columns(size);
    const int width = (size.width() - 2 * kMargin - (cols - 1) * kGap) / cols;
    const int row = index / cols - m_firstRow;
    return {kMargin + (index % cols) * (width + kGap), kTilesTop + row * (kTileHeight + kGap), width, kTileHeight};
}

QRect PickerWindow::startButtonRect(QSize size) const {
    return {size.width() - kMargin - 240, size.height() - 84, 240, 60};
}

QRect PickerWindow::traineeFieldRect(QSize size) const {
    return {kMargin + 170, 104, std::min(420, size.width() - 2 * kMargin - 170), 48};
}

void PickerWindow::select(int index) {
    if (m_content.cases.empty()) return;
    const int was = m_selected;
    m_selected = std::clamp(index, 0, static_cast<int>(m_content.cases.size()) - 1);
    if (m_selected != was) m_status.clear(); // the message was about the case left
    const int row = m_selected / columns(size());
    const int rows = visibleRows(size());
    if (row < m_firstRow) m_firstRow = row;
    if (row >= m_firstRow + rows) m_firstRow = row - rows + 1;
    update();
}

void PickerWindow::setStatus(std::string text, bool error) {
    m_status = std::move(text);
    m_statusError = error;
    update();
}

bool PickerWindow::startSelected() {
    if (m_selected < 0) {
        setStatus("There is no case to start.", true);
        return false;
    }
    const CaseInfo& c = m_content.cases[static_cast<size_t>(m_selected)];
    if (!c.usable()) {
        setStatus("This case cannot be started: " + c.refusal + " — " + c.reason(), true);
        return false;
    }
    if (!m_trainee.empty()) {
        if (std::string why = traineeIdProblem(m_trainee); !why.empty()) {
            setStatus("Not started: " + why, true);
            return false;
        }
    }
    const PlayerCommand command = playerCommand(m_settings, c.path, m_trainee);
    const QPointer<PickerWindow> self(this);
    ExitHandler onExit = [self, title = c.title](int code, const std::string& reason) {
        if (!self) return;
        if (code == 0)
            self->setStatus(title + " ended.", false);
        else
            self->setStatus(title + " stopped (exit " + std::to_string(code) +
                                "): " + (reason.empty() ? "the player gave no reason" : reason),
                            true);
    };
    if (std::string why = m_launch(command, std::move(onExit)); !why.empty()) {
        setStatus("Not started: " + why, true);
        return false;
    }
    setStatus("Started " + c.title + (m_trainee.empty() ? "" : " for trainee " + m_trainee) + ": " + command.display(),
              false);
    return true;
}

int PickerWindow::tileAt(QPointF pos) const {
    for (int i = 0; i < static_cast<int>(m_content.cases.size()); ++i) {
        const QRect r = tileRect(i, size());
        if (r.top() >= kTilesTop && r.bottom() <= size().height() - kFooter && r.contains(pos.toPoint())) return i;
    }
    return -1;
}

void PickerWindow::keyPressEvent(QKeyEvent* e) {
    const int cols = columns(size());
    switch (e->key()) {
    case Qt::Key_Left:
        return select(m_selected - 1);
    case Qt::Key_Right:
        return select(m_selected + 1);
    case Qt::Key_Up:
        return select(m_selected - cols);
    case Qt::Key_Down:
        return select(m_selected + cols);
    case Qt::Key_Home:
        return select(0);
    case Qt::Key_End:
        return select(static_cast<int>(m_content.cases.size()) - 1);
    case Qt::Key_Return:
    case Qt::Key_Enter:
        startSelected();
        return;
    case Qt::Key_Escape:
        close();
        return;
    case Qt::Key_Backspace:
        if (!m_trainee.empty()) m_trainee.pop_back();
        update();
        return;
    default:
        break;
    }
    const QString text = e->text();
    if (text.size() != 1 || !text[0].isPrint()) return;
    const char c = text[0].toLatin1();
    if (!isTraineeIdCharacter(c))
        setStatus("The trainee id may hold only letters, digits and . _ - @", true);
    else if (m_trainee.size() >= kMaxTraineeIdLength)
        setStatus("The trainee id is at most " + std::to_string(kMaxTraineeIdLength) + " characters", true);
    else {
        m_trainee += c;
        update();
    }
}

void PickerWindow::mousePressEvent(QMouseEvent* e) {
    if (e->button() != Qt::LeftButton) return;
    if (startButtonRect(size()).contains(e->position().toPoint())) {
        startSelected();
        return;
    }
    if (const int i = tileAt(e->position()); i >= 0) select(i);
}

void PickerWindow::mouseDoubleClickEvent(QMouseEvent* e) {
    if (e->button() == Qt::LeftButton && tileAt(e->position()) >= 0) startSelected();
}

void PickerWindow::resizeEvent(QResizeEvent*) {
    if (m_selected >= 0) select(m_selected); // keep the selection in view
}

void PickerWindow::paintEvent(QPaintEvent*) {
    QPainter p(this);
    paintWindow(p, size());
}

QImage PickerWindow::render(QSize size) const {
    QImage img(size, QImage::Format_RGB32);
    QPainter p(&img);
    paintWindow(p, size);
    return img;
}

void PickerWindow::paintWindow(QPainter& p, QSize size) const {
    p.fillRect(QRect(QPoint(0, 0), size), kBackground);
    p.setRenderHint(QPainter::Antialiasing, true);
    paintHeader(p, size);
    if (m_content.cases.empty()) {
        paintNoCases(p, size);
    } else {
        for (int i = 0; i < static_cast<int>(m_content.cases.size()); ++i) {
            const QRect r = tileRect(i, size);
            if (r.top() < kTilesTop || r.bottom() > size.height() - kFooter) continue; // scrolled out
            paintTile(p, m_content.cases[static_cast<size_t>(i)], r, i == m_selected);
        }
    }
    paintFooter(p, size);
}

void PickerWindow::paintHeader(QPainter& p, QSize size) const {
    const int w = size.width();
    p.setPen(kText);
    p.setFont(font(30, true));
    p.drawText(QRect(kMargin, 20, w - 2 * kMargin, 40), Qt::AlignLeft | Qt::AlignVCenter, "Choose a case");
    p.setFont(font(17, false));
    p.setPen(kDim);
    p.drawText(QRect(kMargin, 62, w - 2 * kMargin, 28), Qt::AlignLeft | Qt::AlignVCenter,
               "Arrow keys or a click choose  ·  Enter or Start begins  ·  Esc quits");
    // The trainee id field: always takes what is typed (no focus to give it).
    p.setFont(font(20, true));
    p.setPen(kText);
    const QRect field = traineeFieldRect(size);
    p.drawText(QRect(kMargin, field.top(), 160, field.height()), Qt::AlignLeft | Qt::AlignVCenter, "Trainee ID");
    p.setPen(QPen(kAccent, 2));
    p.setBrush(QColor(14, 15, 18));
    p.drawRoundedRect(field, 6, 6);
    p.setFont(font(22, false));
    const QRect inner = field.adjusted(14, 0, -14, 0);
    if (m_trainee.empty()) {
        p.setPen(QColor(110, 114, 120));
        p.drawText(inner.adjusted(8, 0, 0, 0), Qt::AlignLeft | Qt::AlignVCenter, "type your id");
    } else {
        p.setPen(kText);
        p.drawText(inner, Qt::AlignLeft | Qt::AlignVCenter, q(m_trainee));
    }
    const int caretX = inner.left() + (m_trainee.empty() ? 0 : p.fontMetrics().horizontalAdvance(q(m_trainee))) + 2;
    p.fillRect(QRect(std::min(caretX, inner.right()), field.top() + 10, 2, field.height() - 20), kText);
}

void PickerWindow::paintTile(QPainter& p, const CaseInfo& c, QRect r, bool selected) const {
    p.setPen(selected ? QPen(kAccent, 4) : QPen(QColor(70, 74, 82), 1));
    p.setBrush(selected ? QColor(40, 56, 48) : QColor(38, 41, 47));
    p.drawRoundedRect(r.adjusted(2, 2, -2, -2), 10, 10);
    const QRect inner = r.adjusted(20, 14, -20, -14);
    p.setPen(c.usable() ? kText : kError);
    p.setFont(font(24, true));
    const QString title = p.fontMetrics().elidedText(q(c.title), Qt::ElideRight, inner.width());
    p.drawText(QRect(inner.left(), inner.top(), inner.width(), 34), Qt::AlignLeft | Qt::AlignVCenter, title);
    p.setFont(font(17, false));
    p.setPen(kDim);
    const std::string idLine = c.caseId.empty() ? c.path.filename().string() + "  ·  cannot be read"
                                                : c.caseId + "  ·  version " + c.caseVersion;
    p.drawText(QRect(inner.left(), inner.top() + 38, inner.width(), 24), Qt::AlignLeft | Qt::AlignVCenter,
               p.fontMetrics().elidedText(q(idLine), Qt::ElideRight, inner.width()));
    // What verified, or why it cannot run: the trainee sees it before choosing.
    p.setFont(font(16, true));
    p.setPen(c.usable() ? kAccent : kError);
    // Two lines at most; the whole reason is in the status line when the tile is chosen.
    const QRect verdictBox(inner.left(), inner.top() + 64, inner.width(), 2 * p.fontMetrics().lineSpacing());
    QString verdict = q(c.verdict());
    while (verdict.size() > 8 &&
           p.fontMetrics().boundingRect(verdictBox, Qt::TextWordWrap, verdict).height() > verdictBox.height())
        verdict = verdict.left(verdict.size() - 8) + "…";
    p.drawText(verdictBox, Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap, verdict);
    p.setFont(font(15, false));
    p.setPen(kDim);
    p.drawText(QRect(inner.left(), verdictBox.bottom() + 2, inner.width(), inner.bottom() - verdictBox.bottom() - 2),
               Qt::AlignLeft | Qt::AlignVCenter,
               p.fontMetrics().elidedText(q(c.description()), Qt::ElideRight, inner.width()));
}

void PickerWindow::paintNoCases(QPainter& p, QSize size) const {
    const QRect box(kMargin, kTilesTop, size.width() - 2 * kMargin, size.height() - kTilesTop - kFooter);
    p.setPen(QPen(kError, 2));
    p.setBrush(QColor(44, 32, 32));
    p.drawRoundedRect(box, 10, 10);
    p.setPen(kText);
    p.setFont(font(26, true));
    p.drawText(box.adjusted(24, 20, -24, 0), Qt::AlignLeft | Qt::AlignTop, "No case found");
    QString text = "No .vcase file is in any of these folders:\n";
    for (const auto& f : m_content.searched)
        text += "    " + q(f.string()) + "\n";
    text += "\nInstall the viscera-samples package, copy cases into " + q(userCaseFolder().string()) +
            ",\nor name a folder of cases: viscera-launcher FOLDER";
    p.setFont(font(18, false));
    p.setPen(kDim);
    p.drawText(box.adjusted(24, 70, -24, -20), Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap, text);
}

void PickerWindow::paintFooter(QPainter& p, QSize size) const {
    const QRect button = startButtonRect(size);
    const bool ready = m_selected >= 0 && m_content.cases[static_cast<size_t>(m_selected)].usable();
    p.setPen(Qt::NoPen);
    p.setBrush(ready ? kAccent : QColor(70, 74, 82));
    p.drawRoundedRect(button, 10, 10);
    p.setPen(ready ? QColor(12, 12, 12) : kDim);
    p.setFont(font(26, true));
    p.drawText(button, Qt::AlignCenter, "Start");
    p.setFont(font(16, false));
    p.setPen(m_statusError ? kError : kDim);
    const QRect line(kMargin, button.top(), button.left() - 2 * kMargin, button.height());
    p.drawText(line, Qt::AlignLeft | Qt::AlignVCenter | Qt::TextWordWrap, q(m_status));
}

} // namespace viscera::launcher
