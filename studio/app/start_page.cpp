#include "app/start_page.hpp"

#include <QDir>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QLabel>
#include <QListWidget>
#include <QPushButton>
#include <QSettings>
#include <QVBoxLayout>

namespace viscera::studio {

StartPage::StartPage(QWidget* parent) : QWidget(parent) {
    setObjectName("startPage");
    auto* outer = new QHBoxLayout(this);
    auto* column = new QVBoxLayout;
    outer->addStretch(1);
    outer->addLayout(column, 2);
    outer->addStretch(1);
    auto* title = new QLabel(tr("<h2>Viscera Studio</h2>Build a training case: bodies and materials, paint, "
                                "preview, export a signed case package for the player."),
                             this);
    title->setWordWrap(true);
    column->addStretch(1);
    column->addWidget(title);
    auto* buttons = new QHBoxLayout;
    auto* create = new QPushButton(tr("New project…"), this);
    create->setObjectName("startNew");
    auto* open = new QPushButton(tr("Open project…"), this);
    open->setObjectName("startOpen");
    buttons->addWidget(create);
    buttons->addWidget(open);
    buttons->addStretch();
    column->addLayout(buttons);
    column->addWidget(new QLabel(tr("Recent projects"), this));
    m_recent = new QListWidget(this);
    m_recent->setObjectName("startRecent");
    column->addWidget(m_recent, 2);
    column->addStretch(1);
    connect(create, &QPushButton::clicked, this, &StartPage::newRequested);
    connect(open, &QPushButton::clicked, this, &StartPage::openRequested);
    connect(m_recent, &QListWidget::itemActivated, this, [this](QListWidgetItem* item) {
        if (item->flags() & Qt::ItemIsEnabled) emit openRecent(item->data(Qt::UserRole).toString());
    });
    connect(m_recent, &QListWidget::itemClicked, this, [this](QListWidgetItem* item) {
        if (item->flags() & Qt::ItemIsEnabled) emit openRecent(item->data(Qt::UserRole).toString());
    });
}

QStringList StartPage::recentProjects() {
    return QSettings().value("recentProjects").toStringList();
}

void StartPage::addRecent(const QString& folder, int keep) {
    QStringList list = recentProjects();
    list.removeAll(folder);
    list.prepend(folder);
    while (list.size() > keep)
        list.removeLast();
    QSettings().setValue("recentProjects", list);
}

void StartPage::setRecent(const QStringList& folders) {
    m_recent->clear();
    for (const QString& f : folders) {
        const bool there = QFileInfo::exists(QDir(f).filePath("project.json"));
        auto* item = new QListWidgetItem(there ? QStringLiteral("%1    %2").arg(QDir(f).dirName(), f)
                                               : tr("%1    %2 (no project.json there now)").arg(QDir(f).dirName(), f),
                                         m_recent);
        item->setData(Qt::UserRole, f);
        if (!there) item->setFlags(item->flags() & ~Qt::ItemIsEnabled);
    }
    if (folders.isEmpty()) {
        auto* none = new QListWidgetItem(tr("none yet: New project…, or Open project… on a folder with a project.json"),
                                         m_recent);
        none->setFlags(Qt::NoItemFlags);
    }
}

} // namespace viscera::studio
