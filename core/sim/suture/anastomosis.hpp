#pragma once
/// The end-to-end anastomosis scenario of [B ch. 4]: two coaxial tubes of different diameters with
/// fixed far ends and a gap between their facing ends, a semicircular needle driven around the
/// circumference in a running suture (each stitch: in through the wider tube's wall, across the
/// lumen, out through the narrower tube's wall, four punctures), then the thread pulled to close
/// the gap. Meshes and trajectory are generated in code; the trajectory has a small text format.
#include "sim/mesh/generators.hpp"
#include "sim/suture/suture_sim.hpp"

#include <string>
#include <string_view>

namespace viscera::sim {

struct AnastomosisSpec {
    HollowTubeSpec wide{Vec3(0, 0, -0.013), Vec3(0, 0, -0.001), 0.0038, 0.0050, 33, 2, 8}; ///< lower tube
    HollowTubeSpec narrow{Vec3(0, 0, 0.001), Vec3(0, 0, 0.013), 0.0034, 0.0045, 28, 2, 8}; ///< upper tube
    double needleRadius = 0.0042;                                                          ///< m
    double needleCentre = 0.0062;    ///< radial distance of the needle's centre from the axis, m
    int stitches = 5;                ///< 4 punctures each
    double degreesPerFrame = 3.0;    ///< needle rotation per frame while driving
    int transferFrames = 10;         ///< per leg (out, around, in) between stitches
    double transferDistance = 0.003; ///< m, radial retreat between stitches
    int pullFrames = 200;
    double pullPerSegment = 0.0026; ///< m of pull per outside thread segment (tuned: the gap stops closing beyond)
    double slack = 0.002;           ///< m
};

struct AnastomosisModel {
    std::unique_ptr<TetMesh> wide, narrow;
    std::vector<int32_t> wideFixed, narrowFixed; ///< far-end rings, per body indices
};

/// The two tube meshes (about 1,650 nodes and 5,850 tets for the default spec) and their fixed rings.
AnastomosisModel makeAnastomosisTubes(const AnastomosisSpec& spec);
/// Needle frames: `stitches` full needle turns around the circumference, then the pull.
std::vector<NeedleFrame> makeAnastomosisTrajectory(const AnastomosisSpec& spec);

/// The scenario ready to run (bench_suture, tests): both tubes merged (wide first), their far ends
/// fixed, the recorded trajectory, and a simulation whose needle radius and handle come from
/// `spec` (everything else from `settings`).
struct AnastomosisRun {
    std::unique_ptr<SutureSimulation> sim;
    std::vector<NeedleFrame> frames;
    int32_t narrowOffset = 0; ///< first vertex of the narrow tube in the merged mesh
};
AnastomosisRun makeAnastomosisRun(const AnastomosisSpec& spec, SutureSettings settings);
/// Needle pose grasp parameter that makes radial and circumferential moves pure sticking.
double anastomosisHandle(const AnastomosisSpec& spec);

/// Text format, one frame per line: px py pz qw qx qy qz pull (metres, unit quaternion); '#' comments.
std::string formatTrajectory(const std::vector<NeedleFrame>& frames);
/// Throws viscera::InputError "<origin>: line 12: <rule>".
std::vector<NeedleFrame> parseTrajectory(std::string_view text, const std::string& origin);

/// Merges several tet meshes into one (vertex and tet indices offset in order).
std::unique_ptr<TetMesh> mergeMeshes(const std::vector<const TetMesh*>& meshes, std::vector<int32_t>* vertexOffsets);

/// Closure figures between two bodies of a merged mesh. Facing boundary vertices: rest distance to
/// the other body within 1.5× the smallest; opposing: facing vertices whose rest projection on the
/// other body's facing surface falls inside a triangle (an overhanging rim, as where tubes of
/// different diameters meet, is facing but not opposing). Gap: largest distance of an opposing
/// vertex, outside the other body, to the other body's facing surface. Interpenetration: largest
/// distance to the other body's surface of a facing vertex that lies inside one of its tets (the
/// tets of its end region: within 3× the smallest distance). Cost: O(facing × (tets + triangles)).
struct ClosureMetrics {
    double maxGap = 0;         ///< m
    double maxPenetration = 0; ///< m, 0 when no vertex is inside the other body
    bool finite = true;
};
class ClosureGauge {
public:
    ClosureGauge(const TetMesh& merged, int32_t firstVertexOfB);
    ClosureMetrics measure(const std::vector<Vec3>& x) const;
    size_t facingVertices() const { return m_facingA.size() + m_facingB.size(); }
    size_t opposingVertices() const { return m_opposingA.size() + m_opposingB.size(); }

private:
    std::vector<int32_t> m_facingA, m_facingB, m_opposingA, m_opposingB;
    std::vector<std::array<int32_t, 3>> m_trisA, m_trisB; // facing boundary triangles
    std::vector<std::array<int32_t, 3>> m_surfA, m_surfB; // boundary triangles of the end regions
    std::vector<Tet> m_tetsA, m_tetsB;                    // tets of the end regions
};

} // namespace viscera::sim
