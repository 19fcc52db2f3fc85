#include "app/anatomy_steps.hpp"

#include "app/document.hpp"
#include "app/import_placement.hpp"
#include "app/selection.hpp"
#include "bake/import.hpp"
#include "project/project.hpp"
#include "project/remesh_cache.hpp"
#include "project/step_result.hpp"

#include <QAction>
#include <QComboBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDir>
#include <QDoubleSpinBox>
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
#include <QSettings>
#include <QSpinBox>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
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

/// The remesh block as Make simulation-ready's settings `chosen` make it (Run remeshes this block;
/// Apply writes it into the body).
void applyChoice(RemeshSource& r, int voxels, int smoothing, const QString& uvMethod, double fillOpenings) {
    r.params.voxelSize = 0;
    r.params.voxelCount = voxels;
    r.params.smoothingIterations = smoothing;
    r.params.fillOpenings = fillOpenings;
    r.uvTransfer = uvMethod == "none"      ? std::nullopt
                   : uvMethod == "closest" ? std::optional(bake::UvTransferMethod::ClosestPoint)
                   : uvMethod == "island"  ? std::optional(bake::UvTransferMethod::IslandLabelled)
                                           : std::optional(bake::UvTransferMethod::SeamCutting);
    if (!r.uvTransfer) r.texture.clear();
}

/// Writes `project`'s text to `file` (the model as it is in the editor, for a child to read with
/// --project-file); false and `why` when it cannot.
bool writeProjectFile(const Project& project, const QString& file, QString* why) {
    std::ofstream f(file.toStdString(), std::ios::binary);
    f << projectJsonText(project);
    if (f.flush()) return true;
    if (why) *why = QObject::tr("%1: cannot be written").arg(file);
    return false;
}

/// The parts' box in file units: the union of the import result's boxes.
std::array<Eigen::Vector3d, 2> partsBounds(const ImportStepResult& r) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const ImportedPartResult& p : r.parts) {
        lo = lo.cwiseMin(Eigen::Vector3d(p.bounds[0][0], p.bounds[0][1], p.bounds[0][2]));
        hi = hi.cwiseMax(Eigen::Vector3d(p.bounds[1][0], p.bounds[1][1], p.bounds[1][2]));
    }
    return {lo, hi};
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
    if (!ok) {
        fail(message);
        return;
    }
    // The child's typed result (project/step_result.hpp); a malformed one is refused by its line.
    const std::filesystem::path file = m_task.resultFile().toStdString();
    try {
        if (name == kImport)
            askPlacement(readStepResult<ImportStepResult>(file));
        else if (name == kReady)
            showRemeshResult(readStepResult<RemeshStepResult>(file));
        else if (name == kTetra)
            showMeshingResult(readStepResult<MeshingStepResult>(file));
    } catch (const std::exception& e) {
        fail(QString::fromUtf8(e.what()));
    }
}

// ---- import -----------------------------------------------------------------------------------

void openAnatomyDialog(QWidget* parent, const QString& projectFolder, const QString& title, const QString& filter,
                       const QString& objectName, bool many, std::function<void(const QStringList&)> chosen) {
    const QString start = QSettings().value(QStringLiteral("studio/anatomyFolder"), projectFolder).toString();
    auto* dlg = new QFileDialog(parent, title, start, filter);
    dlg->setObjectName(objectName);
    dlg->setOption(QFileDialog::DontUseNativeDialog);
    dlg->setFileMode(many ? QFileDialog::ExistingFiles : QFileDialog::ExistingFile);
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    QObject::connect(dlg, &QFileDialog::filesSelected, dlg, [chosen = std::move(chosen)](const QStringList& files) {
        if (!files.isEmpty())
            QSettings().setValue(QStringLiteral("studio/anatomyFolder"), QFileInfo(files[0]).absolutePath());
        chosen(files);
    });
    dlg->open();
}

void AnatomySteps::askImport() {
    openAnatomyDialog(m_window, m_doc->folder(), tr("Import anatomy: parts and an optional PNG texture"),
                      tr("Anatomy (*.obj *.stl *.ply *.gltf *.glb *.fbx *.png)"), "importAnatomyDialog", true,
                      [this](const QStringList& files) {
                          QString why;
                          if (!importAnatomy(files, &why)) fail(why);
                      });
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
    QStringList args{"import", "--result", m_task.resultFile()};
    for (const QString& m : meshes)
        args << QFileInfo(m).absoluteFilePath();
    return run(kImport, args, int(meshes.size()), why);
}

QString copyIntoProject(const QString& projectFolder, const QString& file, QString* why) {
    const QDir project(projectFolder);
    const QString abs = QFileInfo(file).absoluteFilePath();
    if (abs.startsWith(project.absolutePath() + "/")) return abs; // already one of the project's files
    project.mkpath("anatomy");
    QString target = project.filePath("anatomy/" + QFileInfo(file).fileName());
    for (int n = 2; QFileInfo::exists(target); ++n)
        target = project.filePath(
            QString("anatomy/%1-%2.%3").arg(QFileInfo(file).completeBaseName()).arg(n).arg(QFileInfo(file).suffix()));
    if (!QFile::copy(abs, target)) {
        if (why) *why = QObject::tr("%1: cannot be copied into %2").arg(abs, project.filePath("anatomy"));
        return {};
    }
    return target;
}

void AnatomySteps::askPlacement(const ImportStepResult& imported) {
    auto* dlg = new ImportPlacementDialog(partsBounds(imported), int(m_pendingFiles.size()), m_window);
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    connect(dlg, &QDialog::accepted, this, [this, dlg, imported] { applyImport(imported, dlg->placement()); });
    connect(dlg, &QDialog::rejected, this,
            [this] { emit logMessage(tr("%1: cancelled; the project is unchanged").arg(kImport)); });
    m_placement = dlg;
    dlg->open();
}

void AnatomySteps::applyImport(const ImportStepResult& imported, const bake::ImportPlacement& placement) {
    QStringList copied;
    QString why;
    for (const QString& f : m_pendingFiles) {
        const QString c = copyIntoProject(m_doc->folder(), f, &why);
        if (c.isEmpty()) {
            fail(why);
            return;
        }
        copied << c;
    }
    const bool allUv =
        std::all_of(imported.parts.begin(), imported.parts.end(), [](const ImportedPartResult& p) { return p.hasUv; });
    const Project& now = m_doc->project();
    BodyProject body;
    QString name = "anatomy";
    for (int n = 2; std::any_of(now.bodies.begin(), now.bodies.end(),
                                [&](const BodyProject& b) { return b.scene.name == name.toStdString(); });
         ++n)
        name = QString("anatomy%1").arg(n);
    body.scene.name = name.toStdString();
    body.scene.material = now.bodies.empty() ? newBodyMaterial() : now.bodies.front().scene.material;
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
    emit logMessage(tr("Imported %1 part(s) as body '%2'%3, in %4: %5")
                        .arg(r.parts.size())
                        .arg(name)
                        .arg(allUv ? tr(" with their UVs") : tr(" (a part has no UVs: none transferred)"))
                        .arg(QString::fromUtf8(bake::unitLongName(placement.unit).data()))
                        .arg(sizeText(placedSize(partsBounds(imported), placement))));
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
    auto* fill = new QDoubleSpinBox(dlg);
    fill->setObjectName("fillOpenings");
    fill->setRange(0, 100);
    fill->setDecimals(1);
    fill->setSuffix(tr(" mm"));
    fill->setValue(r.params.fillOpenings * 1e3);
    fill->setToolTip(tr("Open parts whose openings are all at most this wide are capped and made solid (an open "
                        "duct becomes a solid one, not a hollow shell); 0: none"));
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
    form->addRow(tr("Fill openings up to"), fill);
    form->addRow(tr("UV transfer"), uv);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close, dlg);
    QPushButton* runButton = buttons->addButton(tr("Run"), QDialogButtonBox::AcceptRole);
    runButton->setObjectName("runRemesh");
    connect(buttons, &QDialogButtonBox::rejected, dlg, &QDialog::close);
    connect(runButton, &QPushButton::clicked, this, [this, voxels, smoothing, uv, fill] {
        QString why;
        if (!makeSimulationReady(voxels->value(), smoothing->value(), uv->currentText(), fill->value() * 1e-3, &why))
            fail(why);
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

bool AnatomySteps::makeSimulationReady(int voxels, int smoothing, const QString& uvMethod, double fillOpenings,
                                       QString* why) {
    const int b = remeshBody();
    if (b < 0) {
        if (why) *why = tr("Make simulation-ready: select a body made from anatomy");
        return false;
    }
    const QString work = m_task.prepare(m_doc->folder(), why);
    if (work.isEmpty()) return false;
    // The body's block as the settings make it, remeshed as export remeshes it (with the parts'
    // placement): Apply keeps this very surface (remesh_cache.hpp).
    Project candidate = m_doc->project();
    BodyProject& body = candidate.bodies[size_t(b)];
    applyChoice(body.mesh.remesh, voxels, smoothing, uvMethod, fillOpenings);
    const QString projectFile = QDir(work).filePath("project.json");
    if (!writeProjectFile(candidate, projectFile, why)) {
        m_task.discard();
        return false;
    }
    const QString name = QString::fromStdString(body.scene.name);
    QStringList args{"remesh",
                     "--project",
                     m_doc->folder(),
                     "--project-file",
                     projectFile,
                     "--body",
                     name,
                     "-o",
                     QDir(work).filePath("remesh.vremesh"),
                     "--result",
                     m_task.resultFile()};
    if (uvMethod != "none") args << "--uv-preview" << QDir(work).filePath("preview.png");
    m_pendingRemesh = {voxels, smoothing, uvMethod, fillOpenings, name};
    return run(kReady, args, 8, why);
}

void AnatomySteps::showRemeshResult(const RemeshStepResult& result) {
    auto* dlg = new QDialog(m_window);
    dlg->setObjectName("simulationReadyResult");
    dlg->setWindowTitle(tr("Simulation-ready surface"));
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    auto* layout = new QVBoxLayout(dlg);
    if (!result.preview.empty()) {
        auto* picture = new QLabel(dlg);
        picture->setObjectName("uvPreview");
        picture->setPixmap(
            QPixmap(QString::fromStdString(result.preview)).scaledToWidth(1100, Qt::SmoothTransformation));
        layout->addWidget(picture);
    }
    QString text = tr("%1 vertices, %2 triangles in %3 s\n")
                       .arg(result.vertices)
                       .arg(result.triangles)
                       .arg(result.seconds, 0, 'f', 1);
    text += tr("checks: closed %1, manifold %2, self-intersecting pairs %3\n")
                .arg(result.closed ? tr("yes") : tr("no"), result.manifold ? tr("yes") : tr("no"))
                .arg(result.selfIntersections);
    for (const UvTransferFigures& m : result.uv)
        text += tr("%1: %2 triangles over two islands, %3 % of the faces stretched over 2×, UV error %4\n")
                    .arg(QString::fromStdString(m.method))
                    .arg(m.overTwoIslands)
                    .arg(m.overThresholdPct, 0, 'f', 2)
                    .arg(m.uvErrorMean, 0, 'g', 3);
    auto* figures = new QLabel(text, dlg);
    figures->setObjectName("remeshFigures");
    layout->addWidget(figures);
    // The surface leaves the task's folder (removed when this returns) for the project's cache
    // folder, under a pending name: Apply gives it its kept name, Discard removes it.
    const QDir project(m_doc->folder());
    project.mkpath("cache");
    static int runs = 0;
    const QString pending = project.filePath(
        QString("cache/.pending-%1-%2.vremesh").arg(QString::fromStdString(result.cacheKey).left(16)).arg(++runs));
    QFile::remove(pending);
    if (!QFile::rename(QString::fromStdString(result.surface), pending))
        emit logMessage(
            tr("%1: cannot be moved to %2; export will remesh").arg(QString::fromStdString(result.surface), pending));
    connect(dlg, &QObject::destroyed, this, [pending] { QFile::remove(pending); });
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Discard, dlg);
    QPushButton* apply = buttons->addButton(tr("Apply to the body"), QDialogButtonBox::AcceptRole);
    apply->setObjectName("applyRemesh");
    connect(buttons->button(QDialogButtonBox::Discard), &QPushButton::clicked, dlg, &QDialog::close);
    const Pending chosen = m_pendingRemesh;
    const std::string key = result.cacheKey;
    connect(apply, &QPushButton::clicked, this, [this, dlg, chosen, key, pending] {
        applyRemesh(chosen, key, pending);
        dlg->close();
    });
    layout->addWidget(buttons);
    m_result = dlg;
    dlg->show();
}

void AnatomySteps::applyRemesh(const Pending& chosen, const std::string& key, const QString& pending) {
    // The body the remesh ran on, by name: the selection or the bodies may have changed since.
    int b = -1;
    const auto& bodies = m_doc->project().bodies;
    for (size_t i = 0; i < bodies.size(); ++i)
        if (QString::fromStdString(bodies[i].scene.name) == chosen.body &&
            bodies[i].mesh.kind == MeshSource::Kind::Remesh)
            b = int(i);
    if (b < 0) {
        fail(tr("Make simulation-ready: the body '%1' made from anatomy is gone").arg(chosen.body));
        return;
    }
    const QString problem = m_doc->edit(
        tr("Make simulation-ready"),
        [&](Project& p) {
            applyChoice(p.bodies.at(size_t(b)).mesh.remesh, chosen.voxels, chosen.smoothing, chosen.uvMethod,
                        chosen.fillOpenings);
        },
        0, Change{Change::Structure});
    if (!problem.isEmpty()) {
        fail(problem);
        return;
    }
    emit logMessage(tr("Made simulation-ready: %1 voxels, %2 UV transfer").arg(chosen.voxels).arg(chosen.uvMethod));
    // Kept under the block's key, when the block is the one remeshed (its parts unchanged since).
    QString why;
    try {
        const RemeshSource& now = m_doc->project().bodies.at(size_t(b)).mesh.remesh;
        if (remeshKey(now) != key) why = tr("the parts changed since the run");
    } catch (const std::exception& e) {
        why = QString::fromUtf8(e.what());
    }
    const QString kept = QString::fromStdString(keptRemeshFile(m_doc->folder().toStdString(), key).string());
    if (why.isEmpty() && QFileInfo::exists(kept)) QFile::remove(kept);
    if (why.isEmpty() && !QFile::rename(pending, kept)) why = tr("%1 cannot be written").arg(kept);
    emit logMessage(why.isEmpty() ? tr("Kept the remeshed surface (%1): export and Tetrahedralize reuse it").arg(kept)
                                  : tr("The remeshed surface is not kept (%1): export will remesh").arg(why));
}

// ---- tetrahedralize -----------------------------------------------------------------------------

bool AnatomySteps::tetrahedralize(QString* why) {
    if (!m_doc->hasProject() || m_doc->folder().isEmpty()) {
        if (why) *why = tr("Tetrahedralize: save the project first");
        return false;
    }
    const int b = m_sel->body();
    if (b < 0 || b >= int(m_doc->project().bodies.size())) {
        if (why) *why = tr("Tetrahedralize: select a body");
        return false;
    }
    const QString work = m_task.prepare(m_doc->folder(), why);
    if (work.isEmpty()) return false;
    const QString projectFile = QDir(work).filePath("project.json");
    if (!writeProjectFile(m_doc->project(), projectFile, why)) {
        m_task.discard();
        return false;
    }
    // The body meshed and checked alone (viscera-studio mesh), not a whole export.
    return run(kTetra,
               {"mesh", m_doc->folder(), "--body",
                QString::fromStdString(m_doc->project().bodies[size_t(b)].scene.name), "--project-file", projectFile,
                "--result", m_task.resultFile()},
               2, why);
}

void AnatomySteps::showMeshingResult(const MeshingStepResult& result) {
    auto* dlg = new QDialog(m_window);
    dlg->setObjectName("tetrahedralizeResult");
    dlg->setWindowTitle(tr("Tetrahedralize"));
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    auto* layout = new QVBoxLayout(dlg);
    const BodyFigures& f = result.body;
    QString text = tr("body %1: %2 nodes, %3 tets, %4 fixed in %5 s%6\n")
                       .arg(QString::fromStdString(f.name))
                       .arg(f.nodes)
                       .arg(f.tets)
                       .arg(f.fixedNodes)
                       .arg(result.seconds, 0, 'f', 1)
                       .arg(result.remeshReused ? tr(" (the kept remesh)") : QString());
    text += tr("quality: min dihedral %1 deg, max dihedral %2 deg, mean ratio min %3\n")
                .arg(f.minDihedralDeg, 0, 'f', 2)
                .arg(f.maxDihedralDeg, 0, 'f', 2)
                .arg(f.minMeanRatio, 0, 'f', 3);
    text += tr("%1 inverted, %2 degenerate, %3 slivers; volume %4 m³\n")
                .arg(f.inverted)
                .arg(f.degenerate)
                .arg(f.slivers)
                .arg(f.volume, 0, 'g', 4);
    if (result.seededPoints > 0)
        text += tr("thin parts: %1 surface point(s) the first refinement missed were seeded and meshed\n")
                    .arg(result.seededPoints);
    const bool unstable = result.requiredSubsteps > result.substeps;
    if (unstable) // the load-time stability rule: the export would refuse this
        text += tr("unstable: stiffness number %1 at %2 substeps per frame; use at least %3 substeps\n")
                    .arg(result.stiffnessNumber, 0, 'g', 3)
                    .arg(result.substeps)
                    .arg(result.requiredSubsteps);
    auto* figures = new QLabel(text, dlg);
    figures->setObjectName("meshingFigures");
    figures->setWordWrap(true);
    layout->addWidget(figures);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close, dlg);
    connect(buttons, &QDialogButtonBox::rejected, dlg, &QDialog::close);
    if (unstable) {
        // The stability check's dead end, turned into the fixes the artist can take here.
        const int substeps = result.requiredSubsteps;
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
    emit logMessage(tr("Tetrahedralized: %1").arg(text.section('\n', 0, 0)));
}

} // namespace viscera::studio
