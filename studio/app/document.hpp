#pragma once
/// The studio's open project: the one model (studio::Project, the same the headless export
/// reads), its folder and the undo stack whose commands edit it.
///
/// Edits are undo commands of two kinds. A typed edit (editMaterial, editSolver,
/// editStiffnessPaint, editLightSamples, editAssessment, editPlacement) holds only the old and new
/// value of what it edits, is checked by the rules the reader applies to that value
/// (sim::validate and the constraint model of the material: no project text is written) and
/// announces what it changed (Change), so the panels and the preview update only that. The
/// general edit() applies a function to a copy of the model and checks the copy by the rules of
/// load and export (the project text written and read back by the project reader); its command
/// holds both models. Either way a value the export would reject never enters the model, undo
/// restores it exactly, and commands with the same merge key (one drag) merge into one step.
#include "project/project.hpp"
#include "render/sample_map.hpp"

#include <QObject>
#include <QString>
#include <QUndoStack>

#include <functional>
#include <memory>

namespace viscera::studio {

/// What the studio gives a body a tissue layer covers when it enters the tissues the hook and the
/// scissors cut beside the layer. The hook's burn is a dose (sim::Dissection: τ_e = Σ ξ ū_e δt /
/// t_ref against the ignition): the layer (160 °C, ξ 0.4) opens after 160 / (0.4 · 170) = 2.4
/// reference frames at the hook's 170 °C, the organ under it after 400 / (0.05 · 170) = 47
/// (0.78 s), longer than a pass of the hook lasts over an edge; so the hook opens the layer and
/// leaves the organ, and the scissors (a cold cut) divide both. Measured on the cholecystectomy:
/// at the layer's own 160 °C / 0.4 the hook's pass burned 80 of the duct's edges and divided it.
inline constexpr double kCoveredBodyIgnitionC = 400;
inline constexpr double kCoveredBodyConductivity = 0.05;
/// Tissue `t` as the organ under a layer (kCoveredBodyIgnitionC, kCoveredBodyConductivity).
inline void coverByLayer(sim::DissectionTissueDesc& t) {
    t.ignitionC = kCoveredBodyIgnitionC;
    t.conductivity = kCoveredBodyConductivity;
}

/// What an edit changed: the panels and the preview redo only what depends on it.
struct Change {
    enum Part : unsigned {
        Material = 1u << 0,     ///< one body's material (body) or every body's (-1)
        Paint = 1u << 1,        ///< stiffness paint strokes of a body or surface
        LightSamples = 1u << 2, ///< light-sample paint of a body
        Texture = 1u << 3,      ///< material-map blocks
        Structure = 1u << 4,    ///< anything else: meshes, names, scene, a new project
        Solver = 1u << 5,       ///< the XPBD solver settings (substeps, dt, damping, ...)
        Assessment = 1u << 6,   ///< the case's assessment (targets, limits, expert levels)
        Scene = 1u << 7,        ///< the scene's instruments, ports, laparoscope, task (no meshing)
        All = ~0u,
    };
    unsigned parts = All;
    int body = -1; ///< the body a Material change edits (-1: any)

    bool only(unsigned mask) const { return (parts & ~mask) == 0; }
    bool touches(unsigned mask) const { return (parts & mask) != 0; }
    static Change everything() { return {}; }
    static Change material(int body) { return {Material, body}; }
};

class Document : public QObject {
    Q_OBJECT
public:
    explicit Document(QObject* parent = nullptr);
    ~Document() override;

    bool hasProject() const { return m_project != nullptr; }
    const Project& project() const { return *m_project; }
    /// The folder project.json lives in; empty for a new project not saved yet.
    const QString& folder() const { return m_folder; }
    QUndoStack* undoStack() { return &m_undo; }
    /// Bumped by every change of the model (edit, undo, redo, open).
    uint64_t revision() const { return m_revision; }

    /// Opens <folder>/project.json. Throws viscera::InputError naming the file, field and rule;
    /// the open project is then unchanged.
    void open(const QString& folder);
    /// A new project (studio::newProject) in `folder`, written there at once.
    void createNew(const QString& folder, const QString& caseId);
    /// Writes project.json atomically into folder() (or `folder`, which then becomes the
    /// project's folder: Save As copies nothing else; files the project names must lie in it).
    /// Marks the undo stack clean. Throws (message names the file) on failure.
    void save();
    void saveAs(const QString& folder);

    /// Applies `fn` to a copy of the model, checks the copy (check()) and, when it passes, pushes
    /// an undo command holding both models. Returns the empty string when applied, else the
    /// check's message (the model is then unchanged). Commands pushed with the same nonzero
    /// `mergeKey` one after another merge into one undo step (a drag).
    /// `what`: what the edit changes (the panels and the preview redo only that).
    QString edit(const QString& text, const std::function<void(Project&)>& fn, int mergeKey = 0,
                 Change what = Change::everything());
    /// Sets body `body`'s material to `material` as one typed undo command (old and new material
    /// only). Checked by the reader's rules for a material (sim::validate, then the constraint
    /// model with its curves) without writing the project; refused with the rule as
    /// "<folder>/project.json: bodies[i].material: <rule>". Same merge rule as edit().
    QString editMaterial(const QString& text, int body, const sim::Material& material, int mergeKey = 0);
    /// The other typed edits, each checked by the reader's rules for its value: the solver
    /// settings (sim::validate(XpbdSettings), XpbdLimits); the stiffness paint of body `body` or
    /// surface `surface` (the other -1; sim::validateStroke per stroke, the weights' order); the
    /// light-sample paint of a body (render::validateSamplePaintOp per operation).
    QString editSolver(const QString& text, const sim::XpbdSettings& settings);
    QString editStiffnessPaint(const QString& text, int body, int surface,
                               const std::optional<StiffnessPaintProject>& paint);
    QString editLightSamples(const QString& text, int body, const std::vector<render::SamplePaintOp>& ops);
    /// The unit, scale and rotation of a body made from anatomy (its remesh block), checked by the
    /// reader's rule for them (placementProblem); announced as a Structure change (the body is
    /// meshed anew).
    QString editPlacement(const QString& text, int body, const bake::ImportPlacement& placement);
    /// The case's assessment (none: no verdict), checked by sim::readAssessment's rules on what
    /// sim::writeAssessment writes of it ("assessment.metrics.path_length_m.expert.sd: ...").
    QString editAssessment(const QString& text, const std::optional<sim::AssessmentDesc>& assessment);
    // Laparoscope and task [issue 57] (document_scene.cpp), announced as Change::Scene.
    /// The case's laparoscope (none: the case has no scope; the out_of_view_s metric then has
    /// nothing to measure and is refused). Checked by the scene reader's rule on what
    /// sim::writeLaparoscope writes of it (sim::readLaparoscope), then the rest tip within the
    /// port's reach (sim::restTipError, World::assemble's rule); refused as
    /// "<folder>/project.json: laparoscope.<field>: <rule>". Same merge rule as edit().
    QString editLaparoscope(const QString& text, const std::optional<sim::LaparoscopeDesc>& value, int mergeKey = 0);
    /// The task shown to the trainee: the case title (vcase::kMaxTitleBytes), the instructions
    /// (sim::kMaxInstructionsBytes) and the ordered steps (sim::kMaxSteps of at most
    /// sim::kMaxStepBytes each), each printable UTF-8 text (the readers' JsonField::displayText),
    /// refused as "<folder>/project.json: <field>: <rule>"; one undo step for all three.
    QString editTask(const QString& text, const std::string& title, const std::string& instructions,
                     const std::vector<std::string>& steps);
    /// The surroundings (render-only scenery primitives, `textures` one per primitive), one undo
    /// step; checked by the project reader's rule for "scenery" (names new among the bodies,
    /// surfaces and probes; radius, axis, angles), refused as "<folder>/project.json:
    /// scenery[i].<field>: <rule>". Announced as Change::Structure (the scene is drawn anew).
    QString editScenery(const QString& text, const std::vector<SceneryProject>& scenery,
                        const std::vector<std::optional<TextureProject>>& textures, int mergeKey = 0);
    // Instruments [issue 57] (document_instruments.cpp), announced as Change::Scene.
    /// Sets instrument `index` of the scene's interaction to `value` as one typed undo command
    /// (old and new instrument only; its case track path follows its name). Checked by the scene
    /// reader's rules for it: the section with `value` in place, written by sim::interactionJson,
    /// read back by sim::readInteractionSection, its names checked against the bodies and
    /// surfaces (sim::checkInteractionNames), the assessment still measurable
    /// (sim::checkAssessmentMeasurable), its track text parsed (sim::InstrumentTrack::parse) and a
    /// port's rest tip (the track's first key) within its insertion (sim::restTipError, the rule
    /// World::assemble applies). Refused as "<folder>/project.json: interaction.instruments[i].
    /// <field>: <rule>", the model unchanged. Same merge rule as edit().
    QString editInstrument(const QString& text, int index, const sim::InstrumentDesc& value, int mergeKey = 0);
    /// Adds an instrument of `kind` driven by the master `hand` ("left", "right" or "any"), one
    /// undo step: named after its kind and new among the instruments (grasper, grasper_2, ...),
    /// with a port (the reader's defaults) above the bodies' bounds on the hand's side and a
    /// resting one-key track whose tip lies just above the bodies, written at once to
    /// tools/<name>.track in the project folder (the project's files enter its folder with the
    /// edit, as imported anatomy does; save writes it again when it changed or went). A clip
    /// applier clips the body the others clip, else the first body; an energy hook in a scene
    /// with no tissue brings one (the first surface, else the first body: the reader's rule). A
    /// project with no "interaction" gets one. Checked by the rules of load (check()).
    QString addInstrument(const QString& text, sim::InstrumentDesc::Kind kind, const std::string& hand);
    /// Removes instrument `index` (its track file stays in the folder; undo brings the
    /// instrument back with its track text), one undo step; the last one takes the
    /// "interaction" block with it (the reader needs at least one instrument). Checked by the
    /// rules of load: an assessment that needs the instrument refuses it.
    QString removeInstrument(const QString& text, int index);
    // Bodies [issue 57 item 7] (document_bodies.cpp), announced as Structure, Scene and Assessment.
    /// Renames body `body` to `name`, one undo step; every reference to the old name in the
    /// model follows it (other bodies' embedded_in, surfaces' from_boundary_of, clip targets,
    /// tissue layers, the assessment's vessel, the suture's gauge). Refused by the reader's rule
    /// for a body name (sim::readName: characters, length, unique) and the rules of load
    /// (check()), as one line "<folder>/project.json: bodies[i].name: <rule>", the model
    /// unchanged. Returns the empty string when done (also when `name` is the body's name).
    QString renameBody(int body, const QString& name);
    /// Removes body `body`, one undo step (undo brings it back exactly). Refused while anything
    /// else in the model names it, naming each reference ("<folder>/project.json: bodies[0].name:
    /// 'liver' is named by bodies[1].embedded_in (change or delete that first)"), or when the
    /// rules of load refuse the result; the model is then unchanged. Returns the empty string
    /// when done.
    QString removeBody(int body);
    /// Adds a tissue layer (a fascia, project.json "surfaces") over the whole boundary of body
    /// `body`, named "fascia" (else "fascia_2", ...) with the reader's default stiffness and
    /// density, one undo step checked by the rules of load. Returns the empty string when done.
    QString addLayer(int body);
    /// Removes tissue layer `surface`, one undo step. Refused while the interaction's tissues
    /// name it ("<folder>/project.json: surfaces[0].name: 'fascia' is named by
    /// interaction.tissues[0].layer (change or delete that first)"); the model is then unchanged.
    QString removeLayer(int surface);
    /// A fresh merge key for one drag or one continuous gesture.
    int newMergeKey() { return ++m_lastMergeKey; }

    /// Empty when `p` passes the rules of load and export that need no meshing: the project
    /// text read back by loadProjectText, and every material built as constraints. Else the
    /// first rule broken, one line ("project.json: bodies[0].material.poisson_ratio: ...").
    static QString check(const Project& p);

signals:
    /// The model changed (any edit, undo, redo, open, new): `what` says what.
    void changed(const viscera::studio::Change& what);
    /// A one-line message for the log dock.
    void logMessage(const QString& line);

private:
    friend class ProjectCommand;
    template <class Slot> friend class ValueCommand;
    void replace(const Project& p, Change what);
    template <class Slot> void setValue(int target, const typename Slot::Value& v);
    template <class Slot>
    QString editValue(const QString& text, int target, const typename Slot::Value& value, int mergeKey);

    std::unique_ptr<Project> m_project;
    QString m_folder;
    QUndoStack m_undo;
    uint64_t m_revision = 0;
    int m_lastMergeKey = 0;
};

} // namespace viscera::studio
