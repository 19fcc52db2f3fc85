#pragma once
/// What shows through a thin membrane: a vessel embedded under a fascia is seen as a darker red
/// band on it. The deferred renderer's subsurface term works within one mesh (its thickness), so
/// a body embedded in another (sim BodyDesc::embeddedIn) under a surface layer is drawn into that
/// layer's colour instead: each surface vertex takes the embedded body's colour with the weight
/// exp(−d / depth), d the distance at rest from the vertex to the body's nearest node, through the
/// mesh's overlay (RenderMesh::overlay; it moves and is cut with the vertices).
#include "render/scene_view.hpp"

namespace viscera::sim {
class World;
}

namespace viscera::render {

struct EmbeddedTint {
    float depth = 0.003f;  ///< m: the distance over which the tint falls to 1/e
    float strength = 0.6f; ///< the largest overlay alpha
};

/// Tints every surface layer of `world` in `view` over the bodies embedded in another body.
/// Returns the surface vertices tinted by more than 5 %. Cost O(#surface vertices × #nodes of the
/// embedded bodies), once at load.
size_t tintSurfacesOverEmbeddedBodies(SceneView& view, const sim::World& world, const EmbeddedTint& tint = {});

} // namespace viscera::render
