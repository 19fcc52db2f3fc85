#include "app/export_runner.hpp"

#include <QCoreApplication>
#include <QDir>
#include <QFileInfo>
#include <QRegularExpression>
#include <QTemporaryDir>

#include <filesystem>
#include <fstream>
#include <system_error>

namespace viscera::studio {

ExportRunner::ExportRunner(QObject* parent) : QObject(parent) {
    m_program = QCoreApplication::applicationFilePath();
}

ExportRunner::~ExportRunner() {
    if (running()) {
        m_process->disconnect(this);
        m_process->kill();
        m_process->waitForFinished(2000);
    }
}

bool ExportRunner::start(const Project& project, const QString& out, QString* why) {
    auto fail = [&](const QString& w) {
        if (why) *why = w;
        return false;
    };
    if (running()) return fail(tr("an export is already running"));
    const QFileInfo target(out);
    if (target.fileName().isEmpty()) return fail(tr("%1: no file name given").arg(out));
    const QFileInfo folder(target.absolutePath());
    if (!folder.isDir()) return fail(tr("%1: the folder does not exist").arg(target.absolutePath()));
    if (!folder.isWritable()) return fail(tr("%1: the folder is not writable").arg(target.absolutePath()));
    if (target.exists() && !target.isFile()) return fail(tr("%1: exists and is not a file").arg(out));
    m_tmp = std::make_unique<QTemporaryDir>(target.absolutePath() + "/.viscera-export-XXXXXX");
    if (!m_tmp->isValid())
        return fail(tr("%1: cannot create a temporary folder (%2)").arg(target.absolutePath(), m_tmp->errorString()));
    const QString projectFile = m_tmp->filePath("project.json");
    {
        std::ofstream f(projectFile.toStdString(), std::ios::binary);
        f << projectJsonText(project);
        if (!f.flush()) {
            cleanUp();
            return fail(tr("%1: cannot be written").arg(projectFile));
        }
    }
    m_out = target.absoluteFilePath();
    m_output.clear();
    m_lineBuffer.clear();
    m_total = static_cast<int>(exportStageCount(project));
    m_done = 0;
    m_cancelled = false;
    m_process = std::make_unique<QProcess>();
    m_process->setProcessChannelMode(QProcess::MergedChannels);
    connect(m_process.get(), &QProcess::readyRead, this, &ExportRunner::readOutput);
    connect(m_process.get(), &QProcess::finished, this, &ExportRunner::onFinished);
    connect(m_process.get(), &QProcess::errorOccurred, this, [this](QProcess::ProcessError e) {
        if (e == QProcess::FailedToStart) onFinished(-1, QProcess::CrashExit);
    });
    const QString casePath = m_tmp->filePath("case.vcase");
    m_process->start(m_program, {"export", QString::fromStdString(project.dir.string()), "-o", casePath,
                                 "--project-file", projectFile});
    emit progress(0, m_total, tr("starting"));
    return true;
}

void ExportRunner::readOutput() {
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
            continue; // e.g. an unsigned case: kept in the output the window shows, not a stage
        if (!m.captured(1).isEmpty()) {
            m_done = m.captured(1).toInt() - 1;
            m_total = m.captured(2).toInt();
        }
        ++m_done;
        m_total = std::max(m_total, m_done + 1);
        emit progress(m_done, m_total, m.captured(3));
    }
}

void ExportRunner::cancel() {
    if (!running()) return;
    m_cancelled = true;
    m_process->kill();
    // SIGKILL cannot be ignored: the child is gone at once (the bound is for one stuck in the
    // kernel); finished() — and the clean-up — has run when this returns.
    m_process->waitForFinished(2000);
}

void ExportRunner::cleanUp() {
    if (m_tmp) m_tmp->remove();
    m_tmp.reset();
}

void ExportRunner::onFinished(int code, QProcess::ExitStatus status) {
    if (m_process) readOutput();
    if (!m_lineBuffer.isEmpty()) m_output += m_lineBuffer, m_lineBuffer.clear();
    QString message;
    bool ok = false;
    if (m_cancelled) {
        message = tr("cancelled");
    } else if (status != QProcess::NormalExit || code != 0) {
        // the child's last error line names the file, field and rule
        const QStringList lines = m_output.split('\n', Qt::SkipEmptyParts);
        message = lines.isEmpty() ? tr("the export failed (exit %1)").arg(code) : lines.back();
        if (code == -1) message = tr("%1: cannot be started").arg(m_program);
    } else {
        std::error_code ec;
        std::filesystem::rename(m_tmp->filePath("case.vcase").toStdString(), m_out.toStdString(), ec);
        if (ec) {
            message = tr("%1: cannot be written (%2)").arg(m_out, QString::fromStdString(ec.message()));
        } else {
            ok = true;
            m_done = m_total;
            emit progress(m_done, m_total, tr("done"));
            message = tr("exported %1").arg(m_out);
        }
    }
    cleanUp();
    if (m_process) m_process->deleteLater(), m_process.release();
    emit finished(ok, message);
}

} // namespace viscera::studio
