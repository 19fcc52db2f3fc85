#pragma once
/// Where the studio's errors are seen: a strip across the top of the main window's centre that
/// shows the last error of an action (open, save, import, meshing, export, the renderer) in full,
/// until the user closes it or the next error replaces it. The log keeps every line; the status
/// bar only the last, and it may lie below the screen's edge on a small screen.
#include <QFrame>
#include <QString>

class QLabel;
class QToolButton;

namespace viscera::studio {

class ErrorBanner : public QFrame {
    Q_OBJECT
public:
    explicit ErrorBanner(QWidget* parent = nullptr);

    /// Shows `line` (one line: file, field, rule) and the banner.
    void showError(const QString& line);
    /// The error shown; empty when the banner is closed.
    QString text() const;
    QLabel* label() { return m_text; }
    QToolButton* closeButton() { return m_close; }

private:
    QLabel* m_text;
    QToolButton* m_close;
};

} // namespace viscera::studio
