#pragma once
// Headless OpenGL context through EGL (private to viscera_render): the Mesa surfaceless platform
// when the client offers it, else the default display; a surfaceless context when the display
// supports EGL_KHR_surfaceless_context, else a 16×16 pbuffer. Rendering goes to FBOs either way.
#include <memory>
#include <string>

namespace viscera::render::gl {

class EglContext {
public:
    /// Returns nullptr and sets `whyNot` (one line) when no OpenGL ≥ 4.1 core context can be made.
    static std::unique_ptr<EglContext> create(std::string* whyNot);
    ~EglContext();
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    bool makeCurrent();
    /// GL loader for Api::load / createGlBackend.
    static void* procAddress(const char* name, void* user);
    /// "EGL 1.5 (surfaceless), OpenGL 4.5 core".
    const std::string& description() const { return m_description; }

private:
    EglContext() = default;
    void* m_display = nullptr;
    void* m_context = nullptr;
    void* m_surface = nullptr;
    std::string m_description;
};

} // namespace viscera::render::gl
