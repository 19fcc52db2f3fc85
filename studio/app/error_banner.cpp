#include "app/error_banner.hpp"

#include <QHBoxLayout>
#include <QLabel>
#include <QStyle>
#include <QToolButton>

namespace viscera::studio {

ErrorBanner::ErrorBanner(QWidget* parent) : QFrame(parent) {
    setObjectName("errorBanner");
    setFrameShape(QFrame::StyledPanel);
    setStyleSheet("#errorBanner { background: #fde7e9; border: 1px solid #b00020; border-radius: 3px; }"
                  "#errorBanner QLabel { color: #5f0010; }");
    auto* icon = new QLabel(this);
    icon->setPixmap(style()->standardIcon(QStyle::SP_MessageBoxCritical).pixmap(20, 20));
    m_text = new QLabel(this);
    m_text->setObjectName("errorBannerText");
    m_text->setWordWrap(true);
    m_text->setTextInteractionFlags(Qt::TextSelectableByMouse); // a path or a rule to copy
    m_close = new QToolButton(this);
    m_close->setObjectName("errorBannerClose");
    m_close->setText(QStringLiteral("×"));
    m_close->setToolTip(tr("Close (the log keeps the message)"));
    m_close->setAutoRaise(true);
    connect(m_close, &QToolButton::clicked, this, [this] {
        m_text->clear();
        hide();
    });
    auto* layout = new QHBoxLayout(this);
    layout->setContentsMargins(8, 4, 4, 4);
    layout->addWidget(icon, 0, Qt::AlignTop);
    layout->addWidget(m_text, 1);
    layout->addWidget(m_close, 0, Qt::AlignTop);
    hide();
}

void ErrorBanner::showError(const QString& line) {
    m_text->setText(line);
    show();
}

QString ErrorBanner::text() const {
    return isHidden() ? QString() : m_text->text();
}

} // namespace viscera::studio
