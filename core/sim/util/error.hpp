#pragma once
/// Error types shared by every Viscera library.
///
/// InputError: bad authoring or case input (a file, a field, an element). The message names the
/// file or the function, the element or field, and the rule that failed, on one line, e.g.
/// "slab.vtet: line 12: tet 3 references vertex 99 (mesh has 50 vertices)".
/// Public-API preconditions broken by the caller throw std::invalid_argument / std::logic_error
/// with a message of the form "sim::TetMesh::fromArrays(): tet 12 has a repeated vertex".
/// Nothing is thrown inside a per-frame step.
#include <stdexcept>
#include <string>

namespace viscera {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

} // namespace viscera
