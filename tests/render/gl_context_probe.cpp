// render_gl_context_available: fails (exit 1, reason on stderr) when no headless OpenGL context can
// be created, so that a CI machine where every GL test skips still fails one test.
#include "render/headless.hpp"

#include <cstdio>
#include <string>

int main() {
    std::string why;
    if (!viscera::render::headlessContextAvailable(&why)) {
        std::fprintf(stderr, "render_gl_context_available: no headless OpenGL 4.1+ context: %s\n", why.c_str());
        return 1;
    }
    return 0;
}
