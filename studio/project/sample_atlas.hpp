#pragma once
/// The texture atlases of the anatomy made by code (the kidney, the hepatocystic triangle): flat
/// tissue colours per UV island, with a faint grid of 16 lines per island so that a stretched or
/// torn UV transfer shows.
#include "bake/texture.hpp"

#include <span>

namespace viscera::studio {

/// One island of an atlas: [x0, x1] × [y0, y1] in UV (v up) and its colour.
struct AtlasRegion {
    double x0, y0, x1, y1;
    bake::Rgb8 colour;
};

/// A size × size atlas: the regions in their colours over a dark background.
bake::Rgb8Image sampleAtlas(int size, std::span<const AtlasRegion> regions);

} // namespace viscera::studio
