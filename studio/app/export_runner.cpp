#include "app/export_runner.hpp"

#include <QDir>
#include <QFileInfo>

#include <filesystem>
#include <fstream>
#include <system_error>

namespace viscera::studio {

ExportRunner::ExportRunner(QObject* parent) : QObject(parent) {
    connect(&m_task, &StudioTask::progress, this, &ExportRunner::progress);
    connect(&m_task, &StudioTask::finished, this, &ExportRunner::onFinished);
}

bool ExportRunner::start(const Project& project, const QString& out, const ExportSigning& signing, QString* why) {
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
    const QString work = m_task.prepare(target.absolutePath(), why);
    if (work.isEmpty()) return false;
    const QString projectFile = QDir(work).filePath("project.json");
    {
        std::ofstream f(projectFile.toStdString(), std::ios::binary);
        f << projectJsonText(project);
        if (!f.flush()) {
            m_task.discard();
            return fail(tr("%1: cannot be written").arg(projectFile));
        }
    }
    m_out = target.absoluteFilePath();
    QStringList args{"export",
                     QString::fromStdString(project.dir.string()),
                     "-o",
                     QDir(work).filePath("case.vcase"),
                     "--project-file",
                     projectFile,
                     "--result",
                     m_task.resultFile()};
    if (signing.isUnsigned())
        args << "--unsigned";
    else
        args << "--sign-key" << signing.keyFile << "--signer" << signing.signer;
    return m_task.start(tr("export"), args, static_cast<int>(exportStageCount(project)), why);
}

void ExportRunner::onFinished(bool ok, const QString& message) {
    if (!ok) {
        emit finished(false, message);
        return;
    }
    try {
        m_result = readStepResult<ExportStepResult>(m_task.resultFile().toStdString());
    } catch (const std::exception& e) {
        emit finished(false, QString::fromUtf8(e.what()));
        return;
    }
    std::error_code ec;
    std::filesystem::rename(QDir(m_task.workDir()).filePath("case.vcase").toStdString(), m_out.toStdString(), ec);
    if (ec) {
        emit finished(false, tr("%1: cannot be written (%2)").arg(m_out, QString::fromStdString(ec.message())));
        return;
    }
    emit finished(
        true, m_result.keyId.empty()
                  ? tr("exported %1, UNSIGNED: players refuse it without --allow-unsigned").arg(m_out)
                  : tr("exported %1, signed by '%2' (%3)")
                        .arg(m_out, QString::fromStdString(m_result.signer), QString::fromStdString(m_result.keyId)));
}

} // namespace viscera::studio
