#include "app/anatomy_steps.hpp"

#include "app/document.hpp"
#include "app/import_placement.hpp"
#include "app/selection.hpp"
#include "bake/import.hpp"
#include "project/project.hpp"

#include <QAction>
#include <QComboBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QMenu>
#include <QPainter>
#include <QPixmap>
#include <QProgressDialog>
#include <QPushButton>
#include <QRegularExpression>
#include <QSettings>
#include <QSpinBox>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

namespace viscera::studio {
namespace {

const QString kImport = QStringLiteral("import anatomy");
const QString kReady = QStringLiteral("make simulation-ready");
const QString kTetra = QStringLiteral("tetrahedralize");

/// The parts seen from above (x right, y up) with the voxel grid the remesh will use over them:
/// the artist sees how coarse the grid is against the anatomy before running.
class GridPreview : public QWidget {
public:
    GridPreview(std::vector<sim::TriMesh> parts, QWidget* parent) : QWidget(parent), m_parts(std::move(parts)) {
        setObjectName("voxelGridPreview");
        setMinimumSize(420, 420);
        for (const sim::TriMesh& m : m_parts) {
            const auto b = m.bounds();
            m_lo = m_lo.cwiseMin(b[0]);
            m_hi = m_hi.cwiseMax(b[1]);
        }
    }
    void setVoxels(int n) {
        m_voxels = n;
        update();
    }
    /// The voxel edge for `n` voxels along the longest axis, m.
    double voxelSize() const { return (m_hi - m_lo).maxCoeff() / std::max(m_voxels, 1); }
    /// The parts' extents, m.
    sim::Vec3 size() const { return m_parts.empty() ? sim::Vec3::Zero() : sim::Vec3(m_hi - m_lo); }

protected:
    void paintEvent(QPaintEvent*) override {
        QPainter p(this);
        p.fillRect(rect(), QColor(28, 22, 22));
        if (m_parts.empty() || !((m_hi - m_lo).maxCoeff() > 0)) return;
        const double span = std::max(m_hi.x() - m_lo.x(), m_hi.y() - m_lo.y());
        const double scale = 0.92 * std::min(width(), height()) / span;
        auto at = [&](double x, double y) {
            return QPointF(0.04 * width() + (x - m_lo.x()) * scale,
                           height() - 0.04 * height() - (y - m_lo.y()) * scale);
        };
        p.setRenderHint(QPainter::Antialiasing);
        const QColor colours[] = {{170, 70, 60}, {214, 186, 140}, {222, 200, 170}, {200, 40, 46}};
        for (size_t i = 0; i < m_parts.size(); ++i) {
            p.setPen(QPen(colours[i % 4], 0.6));
            const auto& pos = m_parts[i].positions();
            for (const sim::Tri& t : m_parts[i].triangles())
                for (int k = 0; k < 3; ++k)
                    p.drawLine(at(pos[t[k]].x(), pos[t[k]].y()), at(pos[t[(k + 1) % 3]].x(), pos[t[(k + 1) % 3]].y()));
        }
        const double v = voxelSize();
        p.setPen(QPen(QColor(120, 200, 255, 150), 1));
        for (double x = m_lo.x(); x <= m_hi.x() + 1e-12; x += v)
            p.drawLine(at(x, m_lo.y()), at(x, m_hi.y()));
        for (double y = m_lo.y(); y <= m_hi.y() + 1e-12; y += v)
            p.drawLine(at(m_lo.x(), y), at(m_hi.x(), y));
    }

private:
    std::vector<sim::TriMesh> m_parts;
    sim::Vec3 m_lo = sim::Vec3::Constant(1e30), m_hi = sim::Vec3::Constant(-1e30);
    int m_voxels = 64;
};

/// A `name value` figure the remesh prints (uv.<method>.<figure> value); none when it is
/// missing or not a finite number (nothing is shown for it).
std::optional<double> figure(const QString& output, const QString& name) {
    const QRegularExpression re("^" + QRegularExpression::escape(name) + " (\\S+)$",
                                QRegularExpression::MultilineOption);
    const auto m = re.match(output);
    if (!m.hasMatch()) return std::nullopt;
    bool ok = false;
    const double v = m.captured(1).toDouble(&ok);
    return ok && std::isfinite(v) ? std::optional(v) : std::nullopt;
}

QString uvOption(const std::optional<bake::UvTransferMethod>& m) {
    if (!m) return "none";
    return *m == bake::UvTransferMethod::ClosestPoint     ? "closest"
           : *m == bake::UvTransferMethod::IslandLabelled ? "island"
                                                          : "seam-cut";
}

} // namespace

AnatomySteps::AnatomySteps(Document* doc, Selection* sel, QWidget* window)
    : QObject(window), m_doc(doc), m_sel(sel), m_window(window) {
    connect(&m_task, &StudioTask::progress, this, [this](int done, int total, const QString& stage) {
        if (!m_progress) return;
        m_progress->setMaximum(total);
        m_progress->setValue(std::min(done, total));
        m_progress->setLabelText(m_task.name() + ": " + stage);
    });
    connect(&m_task, &StudioTask::finished, this, &AnatomySteps::onFinished);
    m_import = new QAction(tr("&Import anatomy…"), this);
    m_import->setObjectName("actionImportAnatomy");
    connect(m_import, &QAction::triggered, this, &AnatomySteps::askImport);
    m_ready = new QAction(tr("Make &simulation-ready…"), this);
    m_ready->setObjectName("actionMakeSimulationReady");
    connect(m_ready, &QAction::triggered, this, &AnatomySteps::askSimulationReady);
    m_tetra = new QAction(tr("&Tetrahedralize…"), this);
    m_tetra->setObjectName("actionTetrahedralize");
    connect(m_tetra, &QAction::triggered, this, [this] {
        QString why;
        if (!tetrahedralize(&why)) fail(why);
    });
}

void AnatomySteps::fail(const QString& line) {
    emit logMessage(line);
    emit failed(line);
}

void AnatomySteps::buildMenu(QMenu* mesh) {
    mesh->addAction(m_ready);
    mesh->addAction(m_tetra);
}

int AnatomySteps::remeshBody() const {
    const int b = m_sel->body();
    if (!m_doc->hasProject() || b < 0 || b >= int(m_doc->project().bodies.size())) return -1;
    return m_doc->project().bodies[size_t(b)].mesh.kind == MeshSource::Kind::Remesh ? b : -1;
}

bool AnatomySteps::run(const QString& name, const QStringList& args, int stages, QString* why) {
    if (!m_task.start(name, args, stages, why)) {
        m_task.discard();
        return false;
    }
    m_progress = new QProgressDialog(name, tr("Cancel"), 0, stages, m_window);
    m_progress->setObjectName("taskProgress");
    m_progress->setWindowTitle(tr("Working"));
    m_progress->setMinimumDuration(0);
    m_progress->setAutoClose(false);
    m_progress->setAutoReset(false);
    m_progress->setAttribute(Qt::WA_DeleteOnClose);
    connect(m_progress, &QProgressDialog::canceled, &m_task, &StudioTask::cancel);
    m_progress->show();
    return true;
}

void AnatomySteps::onFinished(bool ok, const QString& message) {
    if (m_progress) {
        m_progress->disconnect(&m_task);
        m_progress->close();
    }
    const QString name = m_task.name();
    if (!ok && message == tr("cancelled")) {
        emit logMessage(tr("%1: cancelled; the project is unchanged").arg(name));
        return;
    }
    if (name == kImport) {
        ok ? askPlacement(m_task.output()) : fail(message);
    } else if (name == kReady) {
        ok ? showRemeshResult(m_task.output()) : fail(message);
    } else if (name == kTetra) {
        showMeshingResult(ok, m_task.output(), message);
    }
}

// ---- import -----------------------------------------------------------------------------------

void AnatomySteps::askImport() {
    // Opens where the last anatomy came from (the project folder the first time).
    const QString start = QSettings().value(QStringLiteral("studio/anatomyFolder"), m_doc->folder()).toString();
    auto* dlg = new QFileDialog(m_window, tr("Import anatomy: parts and an optional PNG texture"), start,
                                tr("Anatomy (*.obj *.stl *.ply *.gltf *.glb *.fbx *.png)"));
    dlg->setObjectName("importAnatomyDialog");
    dlg->setOption(QFileDialog::DontUseNativeDialog);
    dlg->setFileMode(QFileDialog::ExistingFiles);
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    connect(dlg, &QFileDialog::filesSelected, this, [this](const QStringList& files) {
        if (!files.isEmpty())
            QSettings().setValue(QStringLiteral("studio/anatomyFolder"), QFileInfo(files[0]).absolutePath());
        QString why;
        if (!importAnatomy(files, &why)) fail(why);
    });
    dlg->open();
}

bool AnatomySteps::importAnatomy(const QStringList& files, QString* why) {
    auto fail = [&](const QString& w) {
        if (why) *why = w;
        return false;
    };
    if (!m_doc->hasProject() || m_doc->folder().isEmpty())
        return fail(tr("Import anatomy: save the project first (the parts are copied into its folder)"));
    QStringList meshes, images;
    for (const QString& f : files)
        (QFileInfo(f).suffix().compare("png", Qt::CaseInsensitive) == 0 ? images : meshes).push_back(f);
    if (meshes.isEmpty()) return fail(tr("Import anatomy: choose at least one mesh (OBJ, STL, PLY, glTF, GLB, FBX)"));
    if (images.size() > 1) return fail(tr("Import anatomy: at most one PNG texture (%1 chosen)").arg(images.size()));
    if (m_task.prepare(m_doc->folder(), why).isEmpty()) return false;
    m_pendingFiles = meshes + images;
    QStringList args{"import"};
    for (const QString& m : meshes)
        args << QFileInfo(m).absoluteFilePath();
    return run(kImport, args, int(meshes.size()), why);
}

QString AnatomySteps::copyIntoProject(const QString& file, QString* why) const {
    const QDir project(m_doc->folder());
    const QString abs = QFileInfo(file).absoluteFilePath();
    if (abs.startsWith(project.absolutePath() + "/")) return abs; // already one of the project's files
    project.mkpath("anatomy");
    QString target = project.filePath("anatomy/" + QFileInfo(file).fileName());
    for (int n = 2; QFileInfo::exists(target); ++n)
        target = project.filePath(
            QString("anatomy/%1-%2.%3").arg(QFileInfo(file).completeBaseName()).arg(n).arg(QFileInfo(file).suffix()));
    if (!QFile::copy(abs, target)) {
        if (why) *why = tr("%1: cannot be copied into %2").arg(abs, project.filePath("anatomy"));
        return {};
    }
    return target;
}

void AnatomySteps::askPlacement(const QString& output) {
    const auto bounds = importedFileBounds(output);
    if (!bounds) {
        fail(tr("Import anatomy: the import check reported no bounds; the project is unchanged"));
        return;
    }
    auto* dlg = new ImportPlacementDialog(*bounds, int(m_pendingFiles.size()), m_window);
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    connect(dlg, &QDialog::accepted, this, [this, dlg, output] { applyImport(output, dlg->placement()); });
    connect(dlg, &QDialog::rejected, this,
            [this] { emit logMessage(tr("%1: cancelled; the project is unchanged").arg(kImport)); });
    m_placement = dlg;
    dlg->open();
}

void AnatomySteps::applyImport(const QString& output, const bake::ImportPlacement& placement) {
    QStringList copied;
    QString why;
    for (const QString& f : m_pendingFiles) {
        const QString c = copyIntoProject(f, &why);
        if (c.isEmpty()) {
            fail(why);
            return;
        }
        copied << c;
    }
    const bool allUv = !output.contains(QStringLiteral(", uv: no"));
    const Project& now = m_doc->project();
    BodyProject body;
    QString name = "anatomy";
    for (int n = 2; std::any_of(now.bodies.begin(), now.bodies.end(),
                                [&](const BodyProject& b) { return b.scene.name == name.toStdString(); });
         ++n)
        name = QString("anatomy%1").arg(n);
    body.scene.name = name.toStdString();
    body.scene.material = now.bodies.empty() ? newProject(now.dir, "anatomy").bodies[0].scene.material
                                             : now.bodies.front().scene.material;
    body.mesh.kind = MeshSource::Kind::Remesh;
    RemeshSource& r = body.mesh.remesh;
    for (const QString& c : copied)
        if (QFileInfo(c).suffix().compare("png", Qt::CaseInsensitive) == 0)
            r.texture = allUv ? std::filesystem::path(c.toStdString()) : std::filesystem::path();
        else
            r.parts.push_back({c.toStdString(), bake::CsgOp::Union});
    r.uvTransfer = allUv ? std::optional(bake::UvTransferMethod::SeamCutting) : std::nullopt;
    r.placement = placement;
    r.params.voxelCount = 64;
    body.mesh.meshing.facetSize = 0.006;
    body.mesh.meshing.facetDistance = 0.001;
    body.mesh.meshing.cellSize = 0.008;
    const int index = int(now.bodies.size());
    const QString problem = m_doc->edit(
        tr("Import anatomy"), [&](Project& p) { p.bodies.push_back(body); }, 0, Change{Change::Structure});
    if (!problem.isEmpty()) {
        fail(problem);
        return;
    }
    m_sel->set(Selection::Kind::Body, index);
    const auto bounds = importedFileBounds(output);
    emit logMessage(tr("Imported %1 part(s) as body '%2'%3, in %4: %5")
                        .arg(r.parts.size())
                        .arg(name)
                        .arg(allUv ? tr(" with their UVs") : tr(" (a part has no UVs: none transferred)"))
                        .arg(QString::fromUtf8(bake::unitLongName(placement.unit).data()))
                        .arg(bounds ? sizeText(placedSize(*bounds, placement)) : QString()));
}

// ---- make simulation-ready ---------------------------------------------------------------------

void AnatomySteps::askSimulationReady() {
    const int b = remeshBody();
    if (b < 0) {
        fail(tr("Make simulation-ready: select a body made from anatomy (File → Import anatomy…)"));
        return;
    }
    const RemeshSource& r = m_doc->project().bodies[size_t(b)].mesh.remesh;
    std::vector<sim::TriMesh> parts;
    for (const RemeshSource::Part& part : r.parts) {
        try {
            parts.push_back(bake::importSurface(part.file, bake::placedOptions(r.placement)));
        } catch (const std::exception& e) {
            fail(QString::fromUtf8(e.what()));
            return;
        }
    }
    auto* dlg = new QDialog(m_window);
    dlg->setObjectName("simulationReadyDialog");
    dlg->setWindowTitle(tr("Make simulation-ready"));
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    auto* grid = new GridPreview(std::move(parts), dlg);
    auto* voxels = new QSpinBox(dlg);
    voxels->setObjectName("voxels");
    voxels->setRange(8, 512);
    voxels->setValue(r.params.voxelCount);
    auto* smoothing = new QSpinBox(dlg);
    smoothing->setObjectName("smoothing");
    smoothing->setRange(0, 100);
    smoothing->setValue(r.params.smoothingIterations);
    auto* uv = new QComboBox(dlg);
    uv->setObjectName("uvTransfer");
    uv->addItems({"seam-cut", "closest", "island", "none"});
    uv->setCurrentText(uvOption(r.uvTransfer));
    auto* size = new QLabel(dlg);
    size->setObjectName("voxelSize");
    auto* bodySize = new QLabel(sizeText(grid->size()), dlg); // before the long work: a wrong unit shows here
    bodySize->setObjectName("bodySize");
    auto update = [grid, voxels, size] {
        grid->setVoxels(voxels->value());
        size->setText(tr("voxel %1 mm").arg(grid->voxelSize() * 1e3, 0, 'f', 2));
    };
    connect(voxels, &QSpinBox::valueChanged, dlg, update);
    update();
    auto* form = new QFormLayout;
    form->addRow(tr("Body (placed parts)"), bodySize);
    form->addRow(tr("Voxels along the longest axis"), voxels);
    form->addRow(QString(), size);
    form->addRow(tr("Smoothing passes"), smoothing);
    form->addRow(tr("UV transfer"), uv);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close, dlg);
    QPushButton* runButton = buttons->addButton(tr("Run"), QDialogButtonBox::AcceptRole);
    runButton->setObjectName("runRemesh");
    connect(buttons, &QDialogButtonBox::rejected, dlg, &QDialog::close);
    connect(runButton, &QPushButton::clicked, this, [this, voxels, smoothing, uv] {
        QString why;
        if (!makeSimulationReady(voxels->value(), smoothing->value(), uv->currentText(), &why)) fail(why);
    });
    auto* layout = new QHBoxLayout(dlg);
    layout->addWidget(grid, 1);
    auto* side = new QVBoxLayout;
    side->addLayout(form);
    side->addStretch();
    side->addWidget(buttons);
    layout->addLayout(side);
    m_settings = dlg;
    dlg->show();
}

bool AnatomySteps::makeSimulationReady(int voxels, int smoothing, const QString& uvMethod, QString* why) {
    const int b = remeshBody();
    if (b < 0) {
        if (why) *why = tr("Make simulation-ready: select a body made from anatomy");
        return false;
    }
    const RemeshSource& r = m_doc->project().bodies[size_t(b)].mesh.remesh;
    const QString work = m_task.prepare(m_doc->folder(), why);
    if (work.isEmpty()) return false;
    QStringList args{"remesh"};
    for (const RemeshSource::Part& part : r.parts)
        args << QString::fromStdString(part.file.string());
    // The remesh command has no rotation: the preview's surface is remeshed in the files' frame
    // (its figures do not depend on it); export meshes the placed parts (project.cpp).
    args << "--scale" << QString::number(r.placement.metresPerFileUnit(), 'g', 17) << "--voxels"
         << QString::number(voxels) << "--smooth" << QString::number(smoothing);
    if (uvMethod == "none")
        args << "--no-uv";
    else
        args << "--uv-transfer" << uvMethod << "--uv-preview" << QDir(work).filePath("preview.png");
    args << "-o" << QDir(work).filePath("result.obj");
    m_pendingRemesh = {voxels, smoothing, uvMethod,
                       QString::fromStdString(m_doc->project().bodies[size_t(b)].scene.name)};
    return run(kReady, args, 8, why);
}

void AnatomySteps::showRemeshResult(const QString& output) {
    auto* dlg = new QDialog(m_window);
    dlg->setObjectName("simulationReadyResult");
    dlg->setWindowTitle(tr("Simulation-ready surface"));
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    auto* layout = new QVBoxLayout(dlg);
    const QString png = QDir(m_task.workDir()).filePath("preview.png");
    if (QFileInfo::exists(png)) {
        auto* picture = new QLabel(dlg);
        picture->setObjectName("uvPreview");
        picture->setPixmap(QPixmap(png).scaledToWidth(1100, Qt::SmoothTransformation));
        layout->addWidget(picture);
    }
    QString text;
    const QRegularExpression checks("^checks: .*$", QRegularExpression::MultilineOption);
    if (const auto m = checks.match(output); m.hasMatch()) text += m.captured(0) + "\n";
    for (const QString& method : {QStringLiteral("closest"), QStringLiteral("island"), QStringLiteral("seam-cut")}) {
        const auto over = figure(output, "uv." + method + ".over_two_islands");
        const auto stretched = figure(output, "uv." + method + ".over_threshold_pct");
        const auto error = figure(output, "uv." + method + ".uv_error_mean");
        if (!over || !stretched || !error) continue;
        text += tr("%1: %2 triangles over two islands, %3 % of the faces stretched over 2×, UV error %4\n")
                    .arg(method)
                    .arg(*over)
                    .arg(*stretched, 0, 'f', 2)
                    .arg(*error, 0, 'g', 3);
    }
    auto* figures = new QLabel(text, dlg);
    figures->setObjectName("remeshFigures");
    layout->addWidget(figures);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Discard, dlg);
    QPushButton* apply = buttons->addButton(tr("Apply to the body"), QDialogButtonBox::AcceptRole);
    apply->setObjectName("applyRemesh");
    connect(buttons->button(QDialogButtonBox::Discard), &QPushButton::clicked, dlg, &QDialog::close);
    const Pending chosen = m_pendingRemesh;
    connect(apply, &QPushButton::clicked, this, [this, dlg, chosen] {
        // The body the remesh ran on, by name: the selection or the bodies may have changed since.
        int b = -1;
        const auto& bodies = m_doc->project().bodies;
        for (size_t i = 0; i < bodies.size(); ++i)
            if (QString::fromStdString(bodies[i].scene.name) == chosen.body &&
                bodies[i].mesh.kind == MeshSource::Kind::Remesh)
                b = int(i);
        if (b < 0) {
            fail(tr("Make simulation-ready: the body '%1' made from anatomy is gone").arg(chosen.body));
            dlg->close();
            return;
        }
        const QString problem = m_doc->edit(
            tr("Make simulation-ready"),
            [&](Project& p) {
                RemeshSource& r = p.bodies.at(size_t(b)).mesh.remesh;
                r.params.voxelSize = 0;
                r.params.voxelCount = chosen.voxels;
                r.params.smoothingIterations = chosen.smoothing;
                r.uvTransfer = chosen.uvMethod == "none"      ? std::nullopt
                               : chosen.uvMethod == "closest" ? std::optional(bake::UvTransferMethod::ClosestPoint)
                               : chosen.uvMethod == "island"  ? std::optional(bake::UvTransferMethod::IslandLabelled)
                                                              : std::optional(bake::UvTransferMethod::SeamCutting);
                if (!r.uvTransfer) r.texture.clear();
            },
            0, Change{Change::Structure});
        if (problem.isEmpty())
            emit logMessage(
                tr("Made simulation-ready: %1 voxels, %2 UV transfer").arg(chosen.voxels).arg(chosen.uvMethod));
        else
            fail(problem);
        dlg->close();
    });
    layout->addWidget(buttons);
    m_result = dlg;
    dlg->show();
}

// ---- tetrahedralize -----------------------------------------------------------------------------

bool AnatomySteps::tetrahedralize(QString* why) {
    if (!m_doc->hasProject() || m_doc->folder().isEmpty()) {
        if (why) *why = tr("Tetrahedralize: save the project first");
        return false;
    }
    const QString work = m_task.prepare(m_doc->folder(), why);
    if (work.isEmpty()) return false;
    const QString projectFile = QDir(work).filePath("project.json");
    {
        std::ofstream f(projectFile.toStdString(), std::ios::binary);
        f << projectJsonText(m_doc->project());
        if (!f.flush()) {
            m_task.discard();
            if (why) *why = tr("%1: cannot be written").arg(projectFile);
            return false;
        }
    }
    return run(kTetra,
               {"export", m_doc->folder(), "-o", QDir(work).filePath("check.vcase"), "--project-file", projectFile,
                "--unsigned"},
               int(exportStageCount(m_doc->project())), why);
}

void AnatomySteps::showMeshingResult(bool ok, const QString& output, const QString& message) {
    auto* dlg = new QDialog(m_window);
    dlg->setObjectName("tetrahedralizeResult");
    dlg->setWindowTitle(tr("Tetrahedralize"));
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    auto* layout = new QVBoxLayout(dlg);
    QString text;
    const QRegularExpression lines("^  (body .*|quality: .*|\\s+\\d+ inverted.*)$",
                                   QRegularExpression::MultilineOption);
    for (auto it = lines.globalMatch(output); it.hasNext();)
        text += it.next().captured(1).trimmed() + "\n";
    if (!ok) text += message + "\n";
    auto* figures = new QLabel(text, dlg);
    figures->setObjectName("meshingFigures");
    figures->setWordWrap(true);
    layout->addWidget(figures);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close, dlg);
    connect(buttons, &QDialogButtonBox::rejected, dlg, &QDialog::close);
    const QRegularExpression needs("use at least (\\d+) substeps");
    if (const auto m = needs.match(message); !ok && m.hasMatch()) {
        // The stability check's dead end, turned into the fixes the artist can take here.
        const int substeps = m.captured(1).toInt();
        const sim::XpbdSettings now = m_doc->project().scene.xpbd;
        auto offer = [&](const QString& label, const QString& objectName, bool possible,
                         const std::function<void(Project&)>& fix) {
            QPushButton* b = buttons->addButton(label, QDialogButtonBox::ActionRole);
            b->setObjectName(objectName);
            b->setEnabled(possible);
            connect(b, &QPushButton::clicked, this, [this, dlg, label, fix] {
                const QString problem = m_doc->edit(label, fix, 0, Change{Change::Structure | Change::Solver});
                dlg->close();
                QString why;
                if (!problem.isEmpty())
                    fail(problem);
                else if (!tetrahedralize(&why))
                    fail(why);
            });
        };
        offer(tr("Use %1 substeps").arg(substeps), "fixSubsteps", substeps <= sim::XpbdLimits::maxSubsteps,
              [substeps](Project& p) { p.scene.xpbd.substeps = substeps; });
        offer(tr("Inertia scaling ×%1").arg(std::min(100.0, std::max(10.0, 10 * now.inertiaScaling))), "fixInertia",
              now.inertiaScaling < sim::XpbdLimits::maxInertiaScaling, [now](Project& p) {
                  p.scene.xpbd.inertiaScaling = std::min(100.0, std::max(10.0, 10 * now.inertiaScaling));
              });
        offer(tr("Coarser cells (×1.5)"), "fixCells", true, [](Project& p) {
            for (BodyProject& b : p.bodies) {
                b.mesh.meshing.cellSize = b.mesh.meshing.cellSize > 0 ? 1.5 * b.mesh.meshing.cellSize : 0.012;
                b.mesh.meshing.facetSize = b.mesh.meshing.facetSize > 0 ? 1.5 * b.mesh.meshing.facetSize : 0.009;
            }
        });
    }
    layout->addWidget(buttons);
    m_result = dlg;
    dlg->show();
    emit logMessage(ok ? tr("Tetrahedralized: %1").arg(text.section('\n', 0, 0)) : message);
}

} // namespace viscera::studio
