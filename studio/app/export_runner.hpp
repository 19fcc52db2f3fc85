#pragma once
/// File → Export case… without blocking the studio: a StudioTask running the same
/// `viscera-studio export` a user runs headless, on the model as it is in the editor (its
/// project text is written to the task's private folder and passed with --project-file; the
/// project's own files still resolve against its folder). So the GUI's package is the CLI's.
///
/// Progress: one step per stage line the child prints. Cancel kills the child at once; the child
/// writes the package inside the task's folder (beside the chosen path) and the runner renames it
/// onto the chosen path only after a successful export, so neither a cancel nor a failure leaves
/// a partial file. The chosen folder is checked writable before anything runs. The signing is
/// always explicit (--sign-key or --unsigned): the window decides it and says it before the work.
#include "app/studio_task.hpp"
#include "project/project.hpp"
#include "project/step_result.hpp"

#include <QObject>
#include <QString>

namespace viscera::studio {

/// How the package is signed: with the publisher key `keyFile` under the name `signer`, or, with
/// no key file, explicitly unsigned (--unsigned: players refuse it without --allow-unsigned).
struct ExportSigning {
    QString keyFile;
    QString signer;
    bool isUnsigned() const { return keyFile.isEmpty(); }
};

class ExportRunner : public QObject {
    Q_OBJECT
public:
    explicit ExportRunner(QObject* parent = nullptr);

    /// The viscera-studio executable to run (default: this program).
    void setProgram(const QString& path) { m_task.setProgram(path); }
    /// Starts exporting `project` to `out`, signed as `signing` says. Returns false and sets `why`
    /// (one line naming the path and the rule) when it cannot start.
    bool start(const Project& project, const QString& out, const ExportSigning& signing, QString* why);
    /// Kills the export and removes what it wrote; finished(false, "cancelled") has been emitted
    /// when it returns.
    void cancel() { m_task.cancel(); }
    bool running() const { return m_task.running(); }
    int stageCount() const { return m_task.stageCount(); }
    int stagesDone() const { return m_task.stagesDone(); }
    /// The child's output so far (stage lines, the export summary or its error).
    const QString& output() const { return m_task.output(); }
    /// The last successful export's typed result (read from the child's --result file); its
    /// casePath is where the child wrote it, before the move onto the chosen path.
    const ExportStepResult& result() const { return m_result; }

signals:
    void progress(int done, int total, const QString& stage);
    /// ok: the package is at the chosen path (`message`: "exported <path>, signed by 'publisher'
    /// (ed25519:…)" or "exported <path>, UNSIGNED: …"); else `message` is the error (or "cancelled").
    void finished(bool ok, const QString& message);

private:
    void onFinished(bool ok, const QString& message);

    StudioTask m_task;
    QString m_out;
    ExportStepResult m_result;
};

} // namespace viscera::studio
