#pragma once
/// The studio's one selection: what the artist picked in the project tree or the viewport. Owned
/// by the main window; the tree, the properties, the material and texture panels, the paint tools
/// and the viewport's outline follow its changed() signal instead of being told one by one.
#include <QObject>

namespace viscera::studio {

class Selection : public QObject {
    Q_OBJECT
public:
    enum class Kind { None, Body, Surface, Instrument, Render, Solver };

    explicit Selection(QObject* parent = nullptr) : QObject(parent) {}

    Kind kind() const { return m_kind; }
    /// Index of the body, surface or instrument (-1 for the others and for none).
    int index() const { return m_index; }
    /// The selected body's index, -1 when the selection is not a body.
    int body() const { return m_kind == Kind::Body ? m_index : -1; }
    /// The selected surface's index, -1 when the selection is not a surface.
    int surface() const { return m_kind == Kind::Surface ? m_index : -1; }

    /// Selects (kind, index); a body, surface or instrument with index < 0 is no selection.
    /// Emits changed() when it differs from the current one.
    void set(Kind kind, int index = -1);
    void clear() { set(Kind::None); }

signals:
    void changed();

private:
    Kind m_kind = Kind::None;
    int m_index = -1;
};

} // namespace viscera::studio
