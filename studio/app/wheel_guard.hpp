#pragma once
/// The mouse wheel never edits a field the artist has not clicked into: over a combo box, spin box
/// or slider without keyboard focus (scrolling a dock past it), the wheel scrolls what holds it
/// instead of changing the value. One application-wide event filter.
#include <QObject>

namespace viscera::studio {

class WheelGuard : public QObject {
    Q_OBJECT
public:
    /// Installs the guard on the running QApplication once (later calls do nothing).
    static void install();

protected:
    bool eventFilter(QObject* watched, QEvent* event) override;

private:
    using QObject::QObject;
};

} // namespace viscera::studio
