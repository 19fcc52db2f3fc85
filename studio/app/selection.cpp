#include "app/selection.hpp"

namespace viscera::studio {

void Selection::set(Kind kind, int index) {
    const bool indexed = kind == Kind::Body || kind == Kind::Surface || kind == Kind::Instrument;
    if (indexed && index < 0) kind = Kind::None;
    if (!indexed) index = -1;
    if (kind == m_kind && index == m_index) return;
    m_kind = kind;
    m_index = index;
    emit changed();
}

} // namespace viscera::studio
