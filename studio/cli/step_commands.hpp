#pragma once
/// `viscera-studio mesh`: one body of a project meshed and checked on its own, as export meshes
/// and checks it (Tetrahedralize runs this, not a whole export) [issue 57 item 6]; and the
/// figures every meshing command prints and hands back in its typed result (step_result.hpp).
#include "project/project.hpp"
#include "project/step_result.hpp"

#include <string>
#include <vector>

/// "  quality: min dihedral … deg, …\n           N inverted, N degenerate, N slivers; volume … m^3".
void printQuality(const viscera::sim::QualityReport& q);

/// The result file's figures of a meshed body.
viscera::studio::BodyFigures bodyFigures(const viscera::studio::BodyExport& b);

/// mesh <project-dir> --body NAME [--project-file JSON] [-o out.vtet] [--result FILE]
int cmdMesh(const std::vector<std::string>& args);

inline constexpr const char* kMeshHelp =
    "usage: viscera-studio mesh <project-dir> --body NAME [--project-file <json>] [-o out.vtet]\n"
    "                           [--result FILE]\n"
    "\n"
    "Meshes one body of a project as export does (its generator, file or remesh block; a remesh\n"
    "kept by the studio's Make simulation-ready is read, not redone), checks its quality (an\n"
    "inverted or degenerate tet is an error) and the solver's load-time stability rule for the\n"
    "body on its own, and prints the figures. Writes no case.\n"
    "  --project-file <json>  read the project from this file instead of <project-dir>/project.json\n"
    "  -o out.vtet            write the tet mesh\n"
    "  --result FILE          write the figures as a typed result (JSON) for the studio\n";
