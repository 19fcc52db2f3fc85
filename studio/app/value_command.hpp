#pragma once
/// Private to the studio's Document (document*.cpp): the typed edit's undo command and the
/// member templates that push and apply it, shared by the files that define typed edits
/// (document.cpp, document_scene.cpp, ...). A Slot names what a typed edit edits:
///   using Value = ...;                                   the value, copied into the command
///   static constexpr int kId;                            unique per Slot (merge id)
///   static Value& of(Project&, int target);              its place in the model
///   static Change change(int target);                    what changing it announces
///   static std::string check(const Project&, int target, const Value&);
///                                                        the reader's rules: empty, or "<path>: <rule>"
#include "app/document.hpp"

#include <QUndoCommand>

namespace viscera::studio {

/// A typed edit: one value of the model before and after, nothing else. A drag (the same nonzero
/// key, the same value) merges into one step, keeping the first `before`.
template <class Slot> class ValueCommand : public QUndoCommand {
public:
    using Value = typename Slot::Value;
    ValueCommand(Document* doc, const QString& text, int target, Value before, Value after, int key)
        : QUndoCommand(text), m_doc(doc), m_target(target), m_before(std::move(before)), m_after(std::move(after)),
          m_key(key) {}
    int id() const override { return m_key ? Slot::kId : -1; }
    bool mergeWith(const QUndoCommand* other) override {
        const auto* o = static_cast<const ValueCommand*>(other);
        if (o->m_key != m_key || o->m_target != m_target) return false;
        m_after = o->m_after;
        return true;
    }
    void redo() override { m_doc->setValue<Slot>(m_target, m_after); }
    void undo() override { m_doc->setValue<Slot>(m_target, m_before); }

private:
    Document* m_doc;
    int m_target;
    Value m_before, m_after;
    int m_key;
};

template <class Slot> void Document::setValue(int target, const typename Slot::Value& v) {
    Slot::of(*m_project, target) = v;
    ++m_revision;
    emit changed(Slot::change(target));
}

template <class Slot>
QString Document::editValue(const QString& text, int target, const typename Slot::Value& value, int mergeKey) {
    if (!m_project) return tr("no project is open");
    if (const std::string why = Slot::check(*m_project, target, value); !why.empty())
        return QString::fromStdString((m_project->dir / "project.json").string() + ": " + why);
    m_undo.push(new ValueCommand<Slot>(this, text, target, Slot::of(*m_project, target), value, mergeKey));
    return {};
}

} // namespace viscera::studio
