#pragma once
/// The launcher's window: a QRasterWindow drawn with QPainter (QtGui only, as the trainee
/// window), a tile per case, a trainee id field and a Start button.
///
/// Keys: arrows (and Home/End) move the selection, Enter starts the selected case, Esc closes
/// the window; letters, digits and . _ - @ go into the trainee id field, Backspace erases. Mouse:
/// a click selects a tile, a double click or the Start button starts it.
#include "case_catalog.hpp"
#include "player_command.hpp"

#include <QImage>
#include <QRasterWindow>
#include <QRect>

#include <filesystem>
#include <string>
#include <vector>

namespace viscera::launcher {

struct PickerContent {
    std::vector<CaseInfo> cases;
    std::vector<std::filesystem::path> searched; ///< the folders looked in (named when none is found)
};

class PickerWindow final : public QRasterWindow {
public:
    PickerWindow(PickerContent content, LaunchSettings settings, Launch launch);

    int selected() const { return m_selected; } ///< index into cases(), -1 when there is none
    const std::string& traineeId() const { return m_trainee; }
    const std::string& status() const { return m_status; } ///< the message line at the bottom
    const std::vector<CaseInfo>& cases() const { return m_content.cases; }
    /// Starts the selected case through the Launch function (what Enter and Start do). False
    /// when nothing was started; status() says why.
    bool startSelected();
    /// The window as drawn, into an image of `size` (for screenshots without a screen grab).
    QImage render(QSize size) const;

    /// Where things are drawn in a window of `size` (mouse hits and tests).
    QRect tileRect(int index, QSize size) const;
    QRect startButtonRect(QSize size) const;
    QRect traineeFieldRect(QSize size) const;

protected:
    void paintEvent(QPaintEvent*) override;
    void keyPressEvent(QKeyEvent* e) override;
    void mousePressEvent(QMouseEvent* e) override;
    void mouseDoubleClickEvent(QMouseEvent* e) override;
    void resizeEvent(QResizeEvent* e) override;

private:
    int columns(QSize size) const;
    int visibleRows(QSize size) const;
    void select(int index);
    void setStatus(std::string text, bool error);
    void paintWindow(QPainter& p, QSize size) const;
    void paintHeader(QPainter& p, QSize size) const;
    void paintTile(QPainter& p, const CaseInfo& c, QRect r, bool selected) const;
    void paintNoCases(QPainter& p, QSize size) const;
    void paintFooter(QPainter& p, QSize size) const;
    int tileAt(QPointF pos) const;

    PickerContent m_content;
    LaunchSettings m_settings;
    Launch m_launch;
    int m_selected = -1;
    int m_firstRow = 0; ///< the first row of tiles shown (the list scrolls to keep the selection)
    std::string m_trainee;
    std::string m_status;
    bool m_statusError = false;
};

} // namespace viscera::launcher
