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
#include <utility>

namespace viscera {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A public-API precondition broken by the caller, with the rule kept apart from the function
/// that checked it, so that a caller can pass the rule on in a message of its own (World names
/// the case file instead of the function). what() is where + rule, e.g.
/// "sim::XpbdSystem::create(): " + "tet body 1 ('vessel'): tet 3 has non-positive rest volume".
struct PreconditionError : std::invalid_argument {
    PreconditionError(const std::string& where, std::string rule)
        : std::invalid_argument(where + rule), rule(std::move(rule)) {}
    std::string rule; ///< the message without the function prefix
};

} // namespace viscera
