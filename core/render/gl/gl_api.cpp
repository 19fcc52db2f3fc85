#include "render/gl/gl_api.hpp"

namespace viscera::render::gl {

bool Api::load(void* (*loader)(const char*, void*), void* user, std::string* missing) {
#define VISCERA_GL_LOAD(type, name)                                                                                    \
    name = reinterpret_cast<type>(loader("gl" #name, user));                                                           \
    if (!name) {                                                                                                       \
        if (missing) *missing = "gl" #name;                                                                            \
        return false;                                                                                                  \
    }
    VISCERA_GL_FUNCTIONS(VISCERA_GL_LOAD)
#undef VISCERA_GL_LOAD
    return true;
}

} // namespace viscera::render::gl
