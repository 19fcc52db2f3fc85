#include "app/tet_import.hpp"

#include "app/anatomy_steps.hpp"
#include "app/document.hpp"
#include "app/selection.hpp"
#include "sim/mesh/gmsh_io.hpp"

#include <QAction>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QInputDialog>
#include <QSettings>

#include <algorithm>
#include <cctype>

namespace viscera::studio {

namespace {

constexpr bake::LengthUnit kUnits[] = {bake::LengthUnit::Metre, bake::LengthUnit::Centimetre,
                                       bake::LengthUnit::Millimetre, bake::LengthUnit::Inch};

/// A body name from the file's base name: letters, digits and '_' (others become '_'), new
/// among `taken`.
std::string bodyName(const QString& file, const std::vector<BodyProject>& bodies) {
    std::string base = QFileInfo(file).completeBaseName().toStdString();
    for (char& c : base)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
    if (base.empty() || std::isdigit(static_cast<unsigned char>(base[0]))) base = "body_" + base;
    base = base.substr(0, 48);
    auto taken = [&](const std::string& n) {
        return std::any_of(bodies.begin(), bodies.end(), [&](const BodyProject& b) { return b.scene.name == n; });
    };
    std::string name = base;
    for (int n = 2; taken(name); ++n)
        name = base + "_" + std::to_string(n);
    return name;
}

} // namespace

TetImport::TetImport(Document* doc, Selection* sel, QWidget* window)
    : QObject(window), m_doc(doc), m_sel(sel), m_window(window) {
    m_action = new QAction(tr("Import &tet mesh…"), this);
    m_action->setObjectName("actionImportTetMesh");
    m_action->setToolTip(tr("A tetrahedral mesh from Gmsh (.msh) or VTK (.vtu) as a tet body, as it is"));
    connect(m_action, &QAction::triggered, this, &TetImport::ask);
}

std::optional<TetImport::Probe> TetImport::probe(const QString& file, QString* why) {
    try {
        const auto mesh = sim::readTetFile(file.toStdString(), 1.0);
        Probe p;
        p.tets = mesh->tets().size();
        p.nodes = mesh->vertexCount();
        Eigen::Vector3d lo = mesh->positions().front(), hi = lo;
        for (const auto& x : mesh->positions()) {
            lo = lo.cwiseMin(x);
            hi = hi.cwiseMax(x);
        }
        p.extent = (hi - lo).maxCoeff();
        p.guess = bake::guessLengthUnit(p.extent);
        return p;
    } catch (const std::exception& e) {
        if (why) *why = QString::fromStdString(e.what());
        return std::nullopt;
    }
}

void TetImport::ask() {
    if (!m_doc->hasProject() || m_doc->folder().isEmpty()) {
        emit failed(tr("Import tet mesh: save the project first (the mesh is copied into its folder)"));
        return;
    }
    openAnatomyDialog(m_window, m_doc->folder(), tr("Import tet mesh"), tr("Tet meshes (*.msh *.vtu *.vtet)"),
                      "importTetMeshDialog", false, [this](const QStringList& files) {
                          if (!files.isEmpty()) askUnit(files.front());
                      });
}

void TetImport::askUnit(const QString& file) {
    QString why;
    const std::optional<Probe> p = probe(file, &why);
    if (!p) {
        emit failed(why);
        return;
    }
    auto* dlg = new QInputDialog(m_window);
    dlg->setObjectName("tetUnitDialog");
    dlg->setAttribute(Qt::WA_DeleteOnClose);
    dlg->setWindowTitle(tr("Import tet mesh"));
    QStringList units;
    for (bake::LengthUnit u : kUnits)
        units << QString::fromUtf8(bake::unitLongName(u).data());
    dlg->setComboBoxItems(units);
    dlg->setTextValue(QString::fromUtf8(bake::unitLongName(p->guess).data()));
    dlg->setLabelText(tr("'%1': %2 tetrahedra, %3 nodes, %4 units long: looks like %5. The file's unit:")
                          .arg(QFileInfo(file).fileName())
                          .arg(p->tets)
                          .arg(p->nodes)
                          .arg(p->extent, 0, 'g', 4)
                          .arg(QString::fromUtf8(bake::unitLongName(p->guess).data())));
    connect(dlg, &QInputDialog::textValueSelected, this, [this, file, p](const QString& text) {
        for (bake::LengthUnit u : kUnits)
            if (text == QString::fromUtf8(bake::unitLongName(u).data())) {
                const QString why = add(file, u, *p); // read once: the probe that asked
                if (!why.isEmpty()) emit failed(why);
            }
    });
    dlg->open();
}

QString TetImport::importFile(const QString& file, bake::LengthUnit unit) {
    if (!m_doc->hasProject() || m_doc->folder().isEmpty())
        return tr("Import tet mesh: save the project first (the mesh is copied into its folder)");
    QString why;
    const std::optional<Probe> p = probe(file, &why); // refused here, nothing is copied
    if (!p) return why;
    return add(file, unit, *p);
}

QString TetImport::add(const QString& file, bake::LengthUnit unit, const Probe& probed) {
    if (!m_doc->hasProject() || m_doc->folder().isEmpty())
        return tr("Import tet mesh: save the project first (the mesh is copied into its folder)");
    const Probe* p = &probed;
    QString why;
    const QString copied = copyIntoProject(m_doc->folder(), file, &why);
    if (copied.isEmpty()) return why;
    const Project& now = m_doc->project();
    BodyProject body;
    body.scene.name = bodyName(file, now.bodies);
    body.scene.material = now.bodies.empty() ? newBodyMaterial() : now.bodies.front().scene.material;
    body.mesh.kind = MeshSource::Kind::File;
    body.mesh.file = copied.toStdString();
    body.mesh.scale = bake::metresPerUnit(unit);
    const int index = static_cast<int>(now.bodies.size());
    const QString name = QString::fromStdString(body.scene.name);
    const QString problem = m_doc->edit(
        tr("Import tet mesh %1").arg(name), [&](Project& pr) { pr.bodies.push_back(body); }, 0,
        Change{Change::Structure});
    if (!problem.isEmpty()) {
        // the project is unchanged, its folder too (a file that was the project's already stays)
        if (QFileInfo(copied).absoluteFilePath() != QFileInfo(file).absoluteFilePath()) QFile::remove(copied);
        return problem;
    }
    m_sel->set(Selection::Kind::Body, index);
    emit logMessage(tr("Imported '%1' as tet body '%2': %3 tetrahedra, %4 m long (%5)")
                        .arg(QFileInfo(file).fileName(), name)
                        .arg(p->tets)
                        .arg(p->extent * bake::metresPerUnit(unit), 0, 'g', 3)
                        .arg(QString::fromUtf8(bake::unitLongName(unit).data())));
    return {};
}

} // namespace viscera::studio
