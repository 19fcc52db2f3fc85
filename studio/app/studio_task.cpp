#include "app/studio_task.hpp"

#include <QCoreApplication>
#include <QFileInfo>
#include <QFutureWatcher>
#include <QRegularExpression>
#include <QTemporaryDir>
#include <QtConcurrent/QtConcurrentRun>

#include <algorithm>

namespace viscera::studio {

StudioTask::StudioTask(QObject* parent) : QObject(parent) {
    m_program = QCoreApplication::applicationFilePath();
}

StudioTask::~StudioTask() {
    if (m_process && m_process->state() != QProcess::NotRunning) {
        m_process->disconnect(this);
        m_process->kill();
        m_process->waitForFinished(2000);
    }
}

QString StudioTask::prepare(const QString& parentDir, QString* why) {
    if (running()) {
        if (why) *why = tr("%1 is already running").arg(m_name);
        return {};
    }
    m_tmp = std::make_unique<QTemporaryDir>(parentDir + "/.viscera-task-XXXXXX");
    ++m_folderGeneration;
    m_fresh = true;
    if (!m_tmp->isValid()) {
        if (why) *why = tr("%1: cannot create a temporary folder (%2)").arg(parentDir, m_tmp->errorString());
        m_tmp.reset();
        return {};
    }
    return m_tmp->path();
}

void StudioTask::discard() {
    if (running()) return;
    m_tmp.reset();
    m_fresh = false;
}

QString StudioTask::workDir() const {
    return m_tmp ? m_tmp->path() : QString();
}

QString StudioTask::resultFile() const {
    return m_tmp ? m_tmp->filePath(QStringLiteral("result.json")) : QString();
}

bool StudioTask::start(const QString& name, const QStringList& args, int stages, QString* why) {
    if (running()) {
        if (why) *why = tr("%1 is already running").arg(m_name);
        return false;
    }
    if (!m_tmp || !m_fresh) { // each run its own folder: the last one's may be removed when it ends
        if (why) *why = tr("%1: no work folder (StudioTask::prepare)").arg(name);
        return false;
    }
    m_fresh = false;
    m_name = name;
    m_output.clear();
    m_lineBuffer.clear();
    m_total = std::max(stages, 1);
    m_done = 0;
    m_cancelled = false;
    m_process = std::make_unique<QProcess>();
    m_process->setProcessChannelMode(QProcess::MergedChannels);
    m_process->setWorkingDirectory(m_tmp->path());
    connect(m_process.get(), &QProcess::readyRead, this, &StudioTask::readOutput);
    connect(m_process.get(), &QProcess::finished, this, &StudioTask::onFinished);
    connect(m_process.get(), &QProcess::errorOccurred, this, [this](QProcess::ProcessError e) {
        if (e == QProcess::FailedToStart) onFinished(-1, QProcess::CrashExit);
    });
    m_process->start(m_program, args);
    emit progress(0, m_total, tr("starting"));
    return true;
}

void StudioTask::readOutput() {
    m_lineBuffer += QString::fromLocal8Bit(m_process->readAll());
    int nl;
    while ((nl = m_lineBuffer.indexOf('\n')) >= 0) {
        const QString line = m_lineBuffer.left(nl);
        m_lineBuffer.remove(0, nl + 1);
        m_output += line + '\n';
        static const QRegularExpression stage(QStringLiteral("^viscera-studio: (?:stage (\\d+)/(\\d+): )?(.*)$"));
        const auto m = stage.match(line);
        if (!m.hasMatch()) continue;
        if (m.captured(1).isEmpty() && m.captured(3).startsWith(QStringLiteral("warning:")))
            continue; // e.g. an unsigned case: kept in the output, not a stage
        if (!m.captured(1).isEmpty()) {
            m_done = m.captured(1).toInt() - 1;
            m_total = m.captured(2).toInt();
        }
        ++m_done;
        m_total = std::max(m_total, m_done + 1);
        emit progress(m_done, m_total, m.captured(3));
    }
}

void StudioTask::runInProcess(const QString& name, std::function<std::any()> work, std::function<void(std::any)> done) {
    m_name = name;
    const uint64_t generation = ++m_inProcessGeneration;
    m_inProcessRunning = true;
    m_total = 1;
    m_done = 0;
    emit progress(0, 1, tr("starting"));
    auto* watcher = new QFutureWatcher<std::any>(this);
    connect(watcher, &QFutureWatcherBase::finished, this, [this, watcher, generation, done] {
        watcher->deleteLater();
        if (generation != m_inProcessGeneration) return; // superseded or cancelled
        m_inProcessRunning = false;
        m_done = 1;
        done(watcher->result());
        emit progress(1, 1, tr("done"));
        emit finished(true, QString());
    });
    watcher->setFuture(QtConcurrent::run(std::move(work)));
}

void StudioTask::cancel() {
    if (m_inProcessRunning) {
        ++m_inProcessGeneration; // its result is dropped
        m_inProcessRunning = false;
        emit finished(false, tr("cancelled"));
        return;
    }
    if (!running()) return;
    m_cancelled = true;
    m_process->kill();
    // SIGKILL cannot be ignored: the child is gone at once (the bound is for one stuck in the
    // kernel); finished() has been emitted when this returns.
    m_process->waitForFinished(2000);
}

void StudioTask::onFinished(int code, QProcess::ExitStatus status) {
    if (m_process) readOutput();
    if (!m_lineBuffer.isEmpty()) m_output += m_lineBuffer, m_lineBuffer.clear();
    QString message;
    bool ok = false;
    if (m_cancelled) {
        message = tr("cancelled");
    } else if (code == -1) {
        message = tr("%1: cannot be started").arg(m_program);
    } else if (status != QProcess::NormalExit || code != 0) {
        const QStringList lines = m_output.split('\n', Qt::SkipEmptyParts);
        message = lines.isEmpty() ? tr("%1 failed (exit %2)").arg(m_name).arg(code) : lines.back();
    } else {
        ok = true;
        m_done = m_total;
        emit progress(m_done, m_total, tr("done"));
    }
    if (m_process) m_process->deleteLater(), m_process.release();
    const uint64_t mine = m_folderGeneration;
    emit finished(ok, message);
    if (m_folderGeneration == mine) m_tmp.reset(); // the receivers took what they need (unless one prepared anew)
}

} // namespace viscera::studio
