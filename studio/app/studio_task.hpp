#pragma once
/// The studio's one kind of long job (import, remesh, tetrahedralize, export): the same
/// `viscera-studio <command>` a user runs headless, run as a child process in a private temporary
/// folder, so the studio never blocks and a cancel takes effect at once, also inside CGAL or
/// OpenVDB (the child is killed: nothing it wrote survives, the model is untouched).
///
/// Progress: one step per line the child prints as "viscera-studio: [stage i/n: ]<stage>" on its
/// error stream (that line protocol is all that is read from its text). The result is the typed
/// file the child writes with `--result resultFile()` (project/step_result.hpp) and the files it
/// wrote in workDir(), handed back on the UI thread by finished(); the caller reads it with
/// readStepResult and applies it to the model as one undo step.
///
/// Short work that needs no process of its own (the texture panel's live thumbnails) runs the
/// same way in process (runInProcess): on a pool thread, its result handed back on the UI thread;
/// a cancel, or a newer request, drops the running job's result (the job itself ends on its own).
#include <QObject>
#include <QProcess>
#include <QString>
#include <QStringList>

#include <any>
#include <functional>
#include <memory>

class QTemporaryDir;

namespace viscera::studio {

class StudioTask : public QObject {
    Q_OBJECT
public:
    explicit StudioTask(QObject* parent = nullptr);
    ~StudioTask() override;

    /// The viscera-studio executable to run (default: this program).
    void setProgram(const QString& path) { m_program = path; }
    const QString& program() const { return m_program; }

    /// Makes the private folder inside `parentDir` (the folder a result will be moved to, so the
    /// move is a rename) and returns its path, or an empty string and `why` when it cannot.
    /// Call before start(), to place arguments (files the child reads or writes) in it.
    QString prepare(const QString& parentDir, QString* why);
    /// Removes the folder prepare() made, when the run it was for will not start.
    void discard();
    /// Runs `viscera-studio args...` (after prepare(), one run per prepare()); `stages` is the expected number of stage
    /// lines (progress maximum, grown when the child prints more). Returns false and sets `why`
    /// when a task is running or prepare() was not called.
    bool start(const QString& name, const QStringList& args, int stages, QString* why);
    /// Kills the child; finished(false, "cancelled") has been emitted when it returns. An
    /// in-process job's result is dropped (finished(false, "cancelled") at once).
    void cancel();

    /// Runs `work` on a pool thread; `done` gets its result on the UI thread, then finished(true,
    /// "") is emitted. A job started while one runs supersedes it: the older one's result is
    /// dropped. `work` must not touch the model or widgets.
    void runInProcess(const QString& name, std::function<std::any()> work, std::function<void(std::any)> done);

    bool running() const { return (m_process && m_process->state() != QProcess::NotRunning) || m_inProcessRunning; }
    const QString& name() const { return m_name; }
    int stageCount() const { return m_total; }
    int stagesDone() const { return m_done; }
    /// The child's output so far (stdout and stderr, merged).
    const QString& output() const { return m_output; }
    /// The private folder (valid from prepare() until the next prepare() or the task's end is
    /// handled: finished() receivers may read and move files from it).
    QString workDir() const;
    /// <workDir()>/result.json: the typed result file to pass to the child as `--result` (valid
    /// as workDir() is).
    QString resultFile() const;

signals:
    void progress(int done, int total, const QString& stage);
    /// ok: the child succeeded (its files are in workDir() while the signal is handled); else
    /// `message` is the child's last line (it names the file, field and rule) or "cancelled".
    void finished(bool ok, const QString& message);

private:
    void readOutput();
    void onFinished(int code, QProcess::ExitStatus status);

    QString m_program, m_name, m_output, m_lineBuffer;
    std::unique_ptr<QProcess> m_process;
    std::unique_ptr<QTemporaryDir> m_tmp;
    int m_total = 0, m_done = 0;
    bool m_cancelled = false;
    bool m_inProcessRunning = false;
    bool m_fresh = false;               ///< prepare() made a folder no run has used yet
    uint64_t m_folderGeneration = 0;    ///< bumped by every prepare()
    uint64_t m_inProcessGeneration = 0; ///< a job's result is used only when it is the latest
};

} // namespace viscera::studio
