#include "render/gl/egl_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <cstring>
#include <string>

namespace viscera::render::gl {

namespace {
bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    const size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}
std::string eglErrorName(EGLint e) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "EGL error 0x%04x", unsigned(e));
    return buf;
}
} // namespace

std::unique_ptr<EglContext> EglContext::create(std::string* whyNot) {
    auto fail = [&](const std::string& why) -> std::unique_ptr<EglContext> {
        if (whyNot) *whyNot = why;
        return nullptr;
    };
    std::unique_ptr<EglContext> ctx(new EglContext);
    const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    EGLDisplay display = EGL_NO_DISPLAY;
    std::string platform = "default display";
    if (hasExtension(clientExt, "EGL_MESA_platform_surfaceless")) {
        auto getPlatformDisplay =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (getPlatformDisplay) {
            display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            platform = "surfaceless";
        }
    }
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
        display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        platform = "default display";
        if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor))
            return fail("EGL: no display could be initialised (" + eglErrorName(eglGetError()) + ")");
    }
    ctx->m_display = display;
    if (!eglBindAPI(EGL_OPENGL_API)) return fail("EGL: the display offers no desktop OpenGL API");
    const EGLint configAttribs[] = {EGL_SURFACE_TYPE,
                                    EGL_PBUFFER_BIT,
                                    EGL_RENDERABLE_TYPE,
                                    EGL_OPENGL_BIT,
                                    EGL_RED_SIZE,
                                    8,
                                    EGL_GREEN_SIZE,
                                    8,
                                    EGL_BLUE_SIZE,
                                    8,
                                    EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!eglChooseConfig(display, configAttribs, &config, 1, &count) || count < 1)
        return fail("EGL: no OpenGL-renderable pbuffer config on the " + platform);
    const EGLint versions[][2] = {{4, 6}, {4, 5}, {4, 3}, {4, 1}};
    EGLContext context = EGL_NO_CONTEXT;
    int gotMajor = 0, gotMinor = 0;
    for (const auto& v : versions) {
        const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                  v[0],
                                  EGL_CONTEXT_MINOR_VERSION,
                                  v[1],
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                  EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                  EGL_NONE};
        context = eglCreateContext(display, config, EGL_NO_CONTEXT, attribs);
        if (context != EGL_NO_CONTEXT) {
            gotMajor = v[0];
            gotMinor = v[1];
            break;
        }
    }
    if (context == EGL_NO_CONTEXT)
        return fail("EGL: no OpenGL 4.1+ core context on the " + platform + " (" + eglErrorName(eglGetError()) + ")");
    ctx->m_context = context;
    if (!hasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
        const EGLint pb[] = {EGL_WIDTH, 16, EGL_HEIGHT, 16, EGL_NONE};
        ctx->m_surface = eglCreatePbufferSurface(display, config, pb);
        if (ctx->m_surface == EGL_NO_SURFACE) return fail("EGL: cannot create a pbuffer surface");
        platform += ", pbuffer";
    }
    if (!ctx->makeCurrent()) return fail("EGL: eglMakeCurrent failed (" + eglErrorName(eglGetError()) + ")");
    ctx->m_description = "EGL " + std::to_string(major) + "." + std::to_string(minor) + " (" + platform + "), OpenGL " +
                         std::to_string(gotMajor) + "." + std::to_string(gotMinor) + " core";
    return ctx;
}

EglContext::~EglContext() {
    if (!m_display) return;
    eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (m_surface) eglDestroySurface(m_display, m_surface);
    if (m_context) eglDestroyContext(m_display, m_context);
    // The display stays initialised: other contexts of the process may share it.
}

bool EglContext::makeCurrent() {
    return eglMakeCurrent(m_display, m_surface ? m_surface : EGL_NO_SURFACE, m_surface ? m_surface : EGL_NO_SURFACE,
                          m_context) == EGL_TRUE;
}

void* EglContext::procAddress(const char* name, void*) {
    return reinterpret_cast<void*>(eglGetProcAddress(name));
}

} // namespace viscera::render::gl
