#include "app/wheel_guard.hpp"

#include <QAbstractSlider>
#include <QAbstractSpinBox>
#include <QApplication>
#include <QComboBox>
#include <QEvent>
#include <QScrollBar>

namespace viscera::studio {

void WheelGuard::install() {
    QCoreApplication* app = QCoreApplication::instance();
    if (!app || app->property("vsc_wheel_guard").toBool()) return;
    app->setProperty("vsc_wheel_guard", true);
    app->installEventFilter(new WheelGuard(app));
}

bool WheelGuard::eventFilter(QObject* watched, QEvent* event) {
    if (event->type() != QEvent::Wheel) return false;
    auto* w = qobject_cast<QWidget*>(watched);
    if (!w || w->hasFocus()) return false;
    const bool valueField = qobject_cast<QComboBox*>(w) || qobject_cast<QAbstractSpinBox*>(w) ||
                            (qobject_cast<QAbstractSlider*>(w) && !qobject_cast<QScrollBar*>(w));
    if (!valueField) return false;
    // Not this field's: ignored, Qt passes it up to the scroll area (or whatever holds it), in
    // that widget's coordinates.
    event->ignore();
    return true;
}

} // namespace viscera::studio
