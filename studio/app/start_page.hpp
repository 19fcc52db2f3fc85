#pragma once
/// What the studio shows where the viewport goes while no project is open: New project, Open
/// project, and the recent projects (a click opens one), instead of an empty window.
#include <QStringList>
#include <QWidget>

class QListWidget;
class QPushButton;

namespace viscera::studio {

class StartPage : public QWidget {
    Q_OBJECT
public:
    explicit StartPage(QWidget* parent = nullptr);

    /// The recent project folders, newest first (those that no longer hold a project.json are
    /// listed greyed out and cannot be opened).
    void setRecent(const QStringList& folders);
    QListWidget* recentList() { return m_recent; }
    /// The recent project folders of the settings ("recentProjects"), newest first.
    static QStringList recentProjects();
    /// Puts `folder` first in the settings' list, which keeps at most `keep` folders.
    static void addRecent(const QString& folder, int keep);

signals:
    void newRequested();
    void openRequested();
    void openRecent(const QString& folder);

private:
    QListWidget* m_recent = nullptr;
};

} // namespace viscera::studio
