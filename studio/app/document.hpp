#pragma once
/// The studio's open project: the one model (studio::Project, the same the headless export
/// reads), its folder and the undo stack whose commands edit it. Every change goes through
/// edit(): the edited copy is checked by the rules of load and export (the project text is
/// written and read back by the project reader, every body's material is turned into
/// constraints) and refused with that reader's one-line message, so a value the export would
/// reject never enters the model. An undo command holds the model before and after, so undo
/// restores it exactly; commands with the same merge key (one drag) merge into one step.
#include "project/project.hpp"

#include <QObject>
#include <QString>
#include <QUndoStack>

#include <functional>
#include <memory>

namespace viscera::studio {

class Document : public QObject {
    Q_OBJECT
public:
    explicit Document(QObject* parent = nullptr);
    ~Document() override;

    bool hasProject() const { return m_project != nullptr; }
    const Project& project() const { return *m_project; }
    /// The folder project.json lives in; empty for a new project not saved yet.
    const QString& folder() const { return m_folder; }
    QUndoStack* undoStack() { return &m_undo; }
    /// Bumped by every change of the model (edit, undo, redo, open).
    uint64_t revision() const { return m_revision; }

    /// Opens <folder>/project.json. Throws viscera::InputError naming the file, field and rule;
    /// the open project is then unchanged.
    void open(const QString& folder);
    /// A new project (studio::newProject) in `folder`, written there at once.
    void createNew(const QString& folder, const QString& caseId);
    /// Writes project.json atomically into folder() (or `folder`, which then becomes the
    /// project's folder: Save As copies nothing else; files the project names must lie in it).
    /// Marks the undo stack clean. Throws (message names the file) on failure.
    void save();
    void saveAs(const QString& folder);

    /// Applies `fn` to a copy of the model, checks the copy (check()) and, when it passes, pushes
    /// an undo command holding both models. Returns the empty string when applied, else the
    /// check's message (the model is then unchanged). Commands pushed with the same nonzero
    /// `mergeKey` one after another merge into one undo step (a drag).
    QString edit(const QString& text, const std::function<void(Project&)>& fn, int mergeKey = 0);
    /// A fresh merge key for one drag or one continuous gesture.
    int newMergeKey() { return ++m_lastMergeKey; }

    /// Empty when `p` passes the rules of load and export that need no meshing: the project
    /// text read back by loadProjectText, and every material built as constraints. Else the
    /// first rule broken, one line ("project.json: bodies[0].material.poisson_ratio: ...").
    static QString check(const Project& p);

signals:
    /// The model changed (any edit, undo, redo, open, new).
    void changed();
    /// A one-line message for the log dock.
    void logMessage(const QString& line);

private:
    friend class ProjectCommand;
    void replace(const Project& p);

    std::unique_ptr<Project> m_project;
    QString m_folder;
    QUndoStack m_undo;
    uint64_t m_revision = 0;
    int m_lastMergeKey = 0;
};

} // namespace viscera::studio
