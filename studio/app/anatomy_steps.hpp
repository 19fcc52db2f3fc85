#pragma once
/// From render anatomy to a simulation body in the studio [issue 38 item 3]: three steps
/// (File → Import anatomy, Mesh → the other two), each run as a StudioTask (progress, a cancel
/// that takes effect at once) and applied to the model as one undo step.
///
///   Import anatomy…          parts (OBJ/STL/PLY/glTF/GLB/FBX, the import's safety rules) and an
///                            optional PNG texture: checked by `viscera-studio import`, then
///                            their unit (guessed from their size), scale and rotation asked
///                            with the body's size shown (ImportPlacementDialog); copied into
///                            the project's anatomy/ folder, and a new body made from them by a
///                            remesh block (seam-cut UVs when every part has them);
///   Make simulation-ready…   the voxel grid drawn over the parts before running; the remesh with
///                            its UV transfer; then source, closest-point and seam-cut transfers
///                            side by side with a checker, the seam-cut stretch heat map with its
///                            seams, and the share of faces over the stretch threshold; Apply
///                            writes the grid and transfer settings into the body's block;
///   Tetrahedralize…          the selected body meshed and checked alone as export meshes and
///                            checks it (`viscera-studio mesh`, no case written): nodes, tets, min
///                            dihedral, slivers; where the stability check asks for more substeps
///                            than allowed, the fixes offered in place (coarser cells, inertia
///                            scaling, more substeps), each an undoable edit.
/// Each child hands back a typed result file (--result, project/step_result.hpp); Apply of Make
/// simulation-ready keeps the remeshed surface in the project's cache folder (remesh_cache.hpp),
/// so Tetrahedralize and export do not remesh again.
#include "app/import_placement.hpp"
#include "app/studio_task.hpp"
#include "project/step_result.hpp"

#include <QObject>
#include <QPointer>
#include <QProgressDialog>
#include <QString>
#include <QStringList>

#include <functional>

class QAction;
class QDialog;
class QLabel;
class QMenu;
class QWidget;

namespace viscera::studio {

class Document;
class Selection;

/// `file` copied into <projectFolder>/anatomy/ (a free name: "liver-2.obj" beside "liver.obj"),
/// or `file` itself when it is one of the project's files already. Empty on failure, with why.
QString copyIntoProject(const QString& projectFolder, const QString& file, QString* why);

/// The studio's dialog for files made elsewhere (anatomy, tet meshes, surroundings): not native,
/// deleted on close, opened where the last such file came from (`projectFolder` the first time),
/// that folder remembered; the files chosen go to `chosen`. `many`: several files at once.
void openAnatomyDialog(QWidget* parent, const QString& projectFolder, const QString& title, const QString& filter,
                       const QString& objectName, bool many, std::function<void(const QStringList&)> chosen);

class AnatomySteps : public QObject {
    Q_OBJECT
public:
    AnatomySteps(Document* doc, Selection* sel, QWidget* window);

    /// Adds Make simulation-ready and Tetrahedralize to the Mesh menu (Import anatomy belongs to
    /// the File menu: importAction()).
    void buildMenu(QMenu* mesh);
    QAction* importAction() const { return m_import; }
    QAction* simulationReadyAction() const { return m_ready; }
    QAction* tetrahedralizeAction() const { return m_tetra; }

    /// The steps with their inputs (the actions ask for them). Each returns false and sets `why`
    /// (one line) when it cannot start; the result arrives through the task.
    bool importAnatomy(const QStringList& files, QString* why);
    bool makeSimulationReady(int voxels, int smoothing, const QString& uvMethod, double fillOpenings, QString* why);
    bool tetrahedralize(QString* why);

    StudioTask& task() { return m_task; }
    /// The open dialogs (null when closed): the step's settings, its progress, its result.
    QDialog* settingsDialog() const { return m_settings; }
    QProgressDialog* progressDialog() const { return m_progress; }
    QDialog* resultDialog() const { return m_result; }
    /// Import's unit, scale and rotation question (null when closed).
    ImportPlacementDialog* placementDialog() const { return m_placement; }
    /// The body the steps act on: the selected body with a remesh block, else -1.
    int remeshBody() const;

signals:
    void logMessage(const QString& line);
    /// A step failed or cannot start: the one line (also sent to the log), for the window to show.
    void failed(const QString& line);

private:
    void askImport();
    void askSimulationReady();
    bool run(const QString& name, const QStringList& args, int stages, QString* why);
    void onFinished(bool ok, const QString& message);
    struct Pending;
    void askPlacement(const ImportStepResult& imported);
    void applyImport(const ImportStepResult& imported, const bake::ImportPlacement& placement);
    void fail(const QString& line);
    void showRemeshResult(const RemeshStepResult& result);
    void applyRemesh(const Pending& chosen, const std::string& key, const QString& pending);
    void showMeshingResult(const MeshingStepResult& result);

    Document* m_doc;
    Selection* m_sel;
    QWidget* m_window;
    StudioTask m_task;
    QAction *m_import = nullptr, *m_ready = nullptr, *m_tetra = nullptr;
    QPointer<QDialog> m_settings, m_result;
    QPointer<QProgressDialog> m_progress;
    QPointer<ImportPlacementDialog> m_placement;
    QStringList m_pendingFiles; ///< import: the files checked by the running task
    struct Pending {
        int voxels = 0, smoothing = 0;
        QString uvMethod;
        double fillOpenings = 0; ///< m
        QString body;            ///< the body the remesh ran on (by name: the selection may change meanwhile)
    } m_pendingRemesh;
};

} // namespace viscera::studio
