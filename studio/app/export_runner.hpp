#pragma once
/// File → Export case… without blocking the studio: the export runs as a child process, the
/// same `viscera-studio export` a user runs headless, on the model as it is in the editor (its
/// project text is written to a private temporary folder and passed with --project-file; the
/// project's own files still resolve against its folder). So the GUI's package is the CLI's.
///
/// Progress: one step per stage line the child prints. Cancel kills the child at once and
/// removes the temporary folder; the child writes the package inside that folder and the runner
/// renames it onto the chosen path only after a successful export, so neither a cancel nor a
/// failure leaves a partial file. The chosen folder is checked writable before anything runs.
#include "project/project.hpp"

#include <QElapsedTimer>
#include <QObject>
#include <QProcess>
#include <QString>

#include <memory>

class QTemporaryDir;

namespace viscera::studio {

class ExportRunner : public QObject {
    Q_OBJECT
public:
    explicit ExportRunner(QObject* parent = nullptr);
    ~ExportRunner() override;

    /// The viscera-studio executable to run (default: this program).
    void setProgram(const QString& path) { m_program = path; }
    /// Starts exporting `project` to `out`. Returns false and sets `why` (one line naming the
    /// path and the rule) when it cannot start.
    bool start(const Project& project, const QString& out, QString* why);
    /// Kills the export and removes what it wrote; finished(false, "cancelled") has been emitted
    /// when it returns.
    void cancel();
    bool running() const { return m_process && m_process->state() != QProcess::NotRunning; }
    int stageCount() const { return m_total; }
    int stagesDone() const { return m_done; }
    /// The child's output so far (stage lines, the export summary or its error).
    const QString& output() const { return m_output; }

signals:
    void progress(int done, int total, const QString& stage);
    /// ok: the package is at the chosen path; else `message` is the error (or "cancelled").
    void finished(bool ok, const QString& message);

private:
    void readOutput();
    void onFinished(int code, QProcess::ExitStatus status);
    void cleanUp();

    QString m_program, m_out, m_output, m_lineBuffer;
    std::unique_ptr<QProcess> m_process;
    std::unique_ptr<QTemporaryDir> m_tmp;
    int m_total = 0, m_done = 0;
    bool m_cancelled = false;
};

} // namespace viscera::studio
