// OpenGL 4.1+ core backend: G-buffer [A Fig. 7.4], deferred lighting, post-effect chain, output
// encoding and stereo composition, on whatever context is current (headless EGL or a window's).
#include "render/backend.hpp"
#include "render/gl/gl_api.hpp"
#include "render/shader_library.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace viscera::render {

namespace {

constexpr float kThicknessRange = kThicknessMapRange; ///< m: G-buffer thickness 1.0 (the bake's default maximum)
constexpr int kMaxMaterials = 32;                     // as many as the lighting shader's arrays hold
constexpr int kAttributeFloats = 11; ///< static attributes per vertex: rest xyz, thickness, samples, overlay rgba, uv
constexpr GLsizei kAttributeBytes = kAttributeFloats * 4;

std::string expandIncludes(std::string_view source, std::string* error) {
    std::string out;
    size_t pos = 0;
    while (pos < source.size()) {
        size_t end = source.find('\n', pos);
        if (end == std::string_view::npos) end = source.size();
        const std::string_view line = source.substr(pos, end - pos);
        if (line.rfind("#include \"", 0) == 0) {
            const size_t q = line.find('"', 10);
            const std::string_view name = line.substr(10, q - 10);
            const std::string_view inc = shaderSource(name);
            if (inc.empty() && error) *error = "missing shader include " + std::string(name);
            out += inc;
            out += '\n';
        } else {
            out += line;
            out += '\n';
        }
        pos = end + 1;
    }
    return out;
}

class Program {
public:
    Program(const gl::Api& api, const char* vs, const char* fs, std::string* error) : m_gl(api) {
        GLuint shaders[2] = {compile(GL_VERTEX_SHADER, vs, error), compile(GL_FRAGMENT_SHADER, fs, error)};
        if (!shaders[0] || !shaders[1]) return;
        m_id = m_gl.CreateProgram();
        for (GLuint s : shaders)
            m_gl.AttachShader(m_id, s);
        m_gl.LinkProgram(m_id);
        for (GLuint s : shaders)
            m_gl.DeleteShader(s);
        GLint ok = 0;
        m_gl.GetProgramiv(m_id, GL_LINK_STATUS, &ok);
        if (!ok) {
            char log[2048] = {};
            m_gl.GetProgramInfoLog(m_id, sizeof log, nullptr, log);
            if (error && error->empty()) *error = std::string("link ") + vs + " + " + fs + ": " + log;
            m_gl.DeleteProgram(m_id);
            m_id = 0;
        }
    }
    ~Program() {
        if (m_id) m_gl.DeleteProgram(m_id);
    }
    bool ok() const { return m_id != 0; }
    void use() const { m_gl.UseProgram(m_id); }
    GLint loc(const std::string& name) {
        auto it = m_locations.find(name);
        if (it != m_locations.end()) return it->second;
        const GLint l = m_gl.GetUniformLocation(m_id, name.c_str());
        m_locations.emplace(name, l);
        return l;
    }
    void set(const std::string& n, int v) { m_gl.Uniform1i(loc(n), v); }
    void set(const std::string& n, float v) { m_gl.Uniform1f(loc(n), v); }
    void set(const std::string& n, const Eigen::Vector2f& v) { m_gl.Uniform2f(loc(n), v.x(), v.y()); }
    void set(const std::string& n, const Eigen::Vector3f& v) { m_gl.Uniform3f(loc(n), v.x(), v.y(), v.z()); }
    void set(const std::string& n, const Eigen::Matrix4f& m) { m_gl.UniformMatrix4fv(loc(n), 1, GL_FALSE, m.data()); }

private:
    GLuint compile(GLenum type, const char* name, std::string* error) {
        const std::string_view raw = shaderSource(name);
        if (raw.empty()) {
            if (error && error->empty()) *error = std::string("shader ") + name + " is not embedded";
            return 0;
        }
        const std::string text = "#version 410 core\n" + expandIncludes(raw, error);
        const GLuint s = m_gl.CreateShader(type);
        const char* src = text.c_str();
        m_gl.ShaderSource(s, 1, &src, nullptr);
        m_gl.CompileShader(s);
        GLint ok = 0;
        m_gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            char log[4096] = {};
            m_gl.GetShaderInfoLog(s, sizeof log, nullptr, log);
            if (error && error->empty()) *error = std::string("compile ") + name + ": " + log;
            m_gl.DeleteShader(s);
            return 0;
        }
        return s;
    }
    const gl::Api& m_gl;
    GLuint m_id = 0;
    std::unordered_map<std::string, GLint> m_locations;
};

struct RenderTarget {
    GLuint fbo = 0;
    std::vector<GLuint> colour;
    GLuint depth = 0;
    int width = 0, height = 0;
};

struct GpuMesh {
    GLuint vao = 0;
    GLuint position = 0, previous = 0, normal = 0, heat = 0, attributes = 0, index = 0;
    size_t vertices = 0, indices = 0;
    size_t drawIndices = 0;  ///< leading indices drawn (face mask, [A §5.3.1])
    GLuint thicknessMap = 0; ///< the mesh's baked thickness texture (0: none)
};

/// The GPU copies of one material's maps (MaterialMaps), made the first time the material is drawn
/// with them and again only when the material's maps object changes.
struct MaterialTextures {
    std::shared_ptr<const MaterialMaps> source;
    GLuint texture[4] = {0, 0, 0, 0}; ///< diffuse, roughness, metallic, normal (0: none)
    int mask = 0;                     ///< bit i: texture[i] present (the shader's uMapMask)
};

class GlBackend final : public Backend {
public:
    explicit GlBackend(const gl::Api& api) : m_gl(api) {}
    ~GlBackend() override;
    bool init(std::string* whyNot);

    const char* name() const override { return "opengl"; }
    void resize(const FrameLayout& layout) override;
    void createMesh(size_t index, const RenderMesh& mesh) override;
    void updateMesh(size_t index, const RenderMesh& mesh, bool staticChanged) override;
    void updateFaceMask(size_t index, const RenderMesh& mesh) override;
    void runPass(const PassDesc& pass, const PassContext& ctx) override;
    void finish() override { m_gl.Finish(); }
    Image readPixels(ImageStage stage) override;
    std::vector<float> readDepth() override;
    void present(uint32_t framebuffer, int width, int height) override;
    BackendStats stats() const override { return m_stats; }
    std::string deviceName() const override { return m_device; }

private:
    GLuint makeTexture(GLint internal, GLenum format, GLenum type, int w, int h, bool linear);
    RenderTarget makeTarget(int w, int h, const std::vector<std::array<GLenum, 3>>& formats, bool depth);
    void freeTarget(RenderTarget& t);
    RenderTarget& target(Target t);
    GLuint targetTexture(Target t) { return target(t).colour.at(0); }
    void bindTexture(Program& p, const char* uniform, int unit, GLuint texture);
    void beginFullscreen(Program& p, const PassDesc& pass);
    void gbufferPass(const PassDesc& pass, const PassContext& ctx);
    /// The textures of material `index`, uploaded when its maps changed.
    const MaterialTextures& texturesOf(size_t index, const TissueMaterial& material);
    void freeTextures(MaterialTextures& t);
    /// A mip-mapped, repeating 2D texture of `img` (rows flipped into `scratch`).
    GLuint uploadTexture(const Image& img, bool srgb, std::vector<uint8_t>& scratch);
    void lightingPass(const PassDesc& pass, const PassContext& ctx);
    void postPass(const PassDesc& pass, const PassContext& ctx);
    void outputPass(const PassDesc& pass);
    void composePass(const PassDesc& pass);

    const gl::Api& m_gl;
    std::string m_device;
    BackendStats m_stats;
    FrameLayout m_layout;
    std::unique_ptr<Program> m_gbuffer, m_lighting, m_output, m_anaglyph;
    std::unordered_map<int, std::unique_ptr<Program>> m_post; ///< by PassKind
    GLuint m_emptyVao = 0;
    RenderTarget m_gbufferTarget, m_lit, m_postA, m_postB, m_eyeLeft, m_eyeRight, m_final, m_scratch;
    std::vector<GpuMesh> m_meshes;
    std::vector<MaterialTextures> m_materialTextures; ///< by material index
    std::vector<uint32_t> m_maskScratch;              ///< compacted indices of a face mask
    Target m_lastLitSource = Target::Lit;
};

GlBackend::~GlBackend() {
    for (GpuMesh& m : m_meshes) {
        GLuint buffers[] = {m.position, m.previous, m.normal, m.heat, m.attributes, m.index};
        m_gl.DeleteBuffers(6, buffers);
        m_gl.DeleteVertexArrays(1, &m.vao);
        if (m.thicknessMap) m_gl.DeleteTextures(1, &m.thicknessMap);
    }
    for (RenderTarget* t :
         {&m_gbufferTarget, &m_lit, &m_postA, &m_postB, &m_eyeLeft, &m_eyeRight, &m_final, &m_scratch})
        freeTarget(*t);
    if (m_emptyVao) m_gl.DeleteVertexArrays(1, &m_emptyVao);
    for (MaterialTextures& t : m_materialTextures)
        freeTextures(t);
}

void GlBackend::freeTextures(MaterialTextures& t) {
    for (GLuint& tex : t.texture)
        if (tex) {
            m_gl.DeleteTextures(1, &tex);
            tex = 0;
        }
    t.mask = 0;
    t.source.reset();
}

const MaterialTextures& GlBackend::texturesOf(size_t index, const TissueMaterial& material) {
    if (m_materialTextures.size() <= index) m_materialTextures.resize(index + 1);
    MaterialTextures& t = m_materialTextures[index];
    if (t.source == material.maps) return t;
    freeTextures(t);
    t.source = material.maps;
    if (!material.maps) return t;
    const Image* images[4] = {&material.maps->diffuse, &material.maps->roughness, &material.maps->metallic,
                              &material.maps->normal};
    std::vector<uint8_t> flipped;
    for (int k = 0; k < 4; ++k) {
        const Image& img = *images[k];
        if (img.empty() || img.width <= 0 || img.height <= 0 ||
            img.rgba.size() != size_t(img.width) * size_t(img.height) * 4)
            continue;
        t.texture[k] = uploadTexture(img, k == 0, flipped);
        t.mask |= 1 << k;
    }
    return t;
}

GLuint GlBackend::uploadTexture(const Image& img, bool srgb, std::vector<uint8_t>& flipped) {
    // texture row 0 is the image's bottom row: v = 0 at the bottom, as UVs are given
    flipped.resize(img.rgba.size());
    const size_t row = size_t(img.width) * 4;
    for (int y = 0; y < img.height; ++y)
        std::copy_n(img.rgba.begin() + ptrdiff_t(row * (img.height - 1 - y)), row,
                    flipped.begin() + ptrdiff_t(row * y));
    GLuint tex = 0;
    m_gl.GenTextures(1, &tex);
    m_gl.BindTexture(GL_TEXTURE_2D, tex);
    m_gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    m_gl.TexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, img.width, img.height, 0, GL_RGBA,
                    GL_UNSIGNED_BYTE, flipped.data());
    m_gl.GenerateMipmap(GL_TEXTURE_2D);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    m_gl.BindTexture(GL_TEXTURE_2D, 0);
    ++m_stats.textureUploads;
    return tex;
}

bool GlBackend::init(std::string* whyNot) {
    GLint major = 0, minor = 0;
    m_gl.GetIntegerv(GL_MAJOR_VERSION, &major);
    m_gl.GetIntegerv(GL_MINOR_VERSION, &minor);
    if (major < 4 || (major == 4 && minor < 1)) {
        if (whyNot) *whyNot = "OpenGL " + std::to_string(major) + "." + std::to_string(minor) + " is older than 4.1";
        return false;
    }
    const char* renderer = reinterpret_cast<const char*>(m_gl.GetString(GL_RENDERER));
    m_device = renderer ? renderer : "unknown";
    std::string error;
    m_gbuffer = std::make_unique<Program>(m_gl, "gbuffer_vs.glsl", "gbuffer_fs.glsl", &error);
    m_lighting = std::make_unique<Program>(m_gl, "fullscreen_vs.glsl", "lighting_fs.glsl", &error);
    m_output = std::make_unique<Program>(m_gl, "fullscreen_vs.glsl", "output_fs.glsl", &error);
    m_anaglyph = std::make_unique<Program>(m_gl, "fullscreen_vs.glsl", "stereo_anaglyph_fs.glsl", &error);
    const std::pair<PassKind, const char*> post[] = {
        {PassKind::DepthOfField, "post_depth_of_field_fs.glsl"},
        {PassKind::ChromaticAberration, "post_chromatic_aberration_fs.glsl"},
        {PassKind::ToneMapping, "post_tone_mapping_fs.glsl"},
        {PassKind::ColourCurve, "post_colour_curve_fs.glsl"},
        {PassKind::Sharpen, "post_sharpen_fs.glsl"},
        {PassKind::Noise, "post_noise_fs.glsl"},
        {PassKind::RadialMask, "post_radial_mask_fs.glsl"}};
    for (const auto& [kind, file] : post)
        m_post[int(kind)] = std::make_unique<Program>(m_gl, "fullscreen_vs.glsl", file, &error);
    if (!error.empty()) {
        if (whyNot) *whyNot = "shader error: " + error;
        return false;
    }
    m_gl.GenVertexArrays(1, &m_emptyVao);
    return true;
}

GLuint GlBackend::makeTexture(GLint internal, GLenum format, GLenum type, int w, int h, bool linear) {
    GLuint t = 0;
    m_gl.GenTextures(1, &t);
    m_gl.BindTexture(GL_TEXTURE_2D, t);
    m_gl.TexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, format, type, nullptr);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, linear ? GL_LINEAR : GL_NEAREST);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, linear ? GL_LINEAR : GL_NEAREST);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    m_gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

RenderTarget GlBackend::makeTarget(int w, int h, const std::vector<std::array<GLenum, 3>>& formats, bool depth) {
    RenderTarget t;
    t.width = w;
    t.height = h;
    m_gl.GenFramebuffers(1, &t.fbo);
    m_gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    std::vector<GLenum> draw;
    for (size_t i = 0; i < formats.size(); ++i) {
        const bool linear = formats.size() == 1; // G-buffer attachments are read texel by texel
        const GLuint tex = makeTexture(GLint(formats[i][0]), formats[i][1], formats[i][2], w, h, linear);
        m_gl.FramebufferTexture2D(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GL_TEXTURE_2D, tex, 0);
        t.colour.push_back(tex);
        draw.push_back(GLenum(GL_COLOR_ATTACHMENT0 + i));
    }
    if (depth) {
        t.depth = makeTexture(GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, w, h, false);
        m_gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, t.depth, 0);
    }
    m_gl.DrawBuffers(GLsizei(draw.size()), draw.data());
    ++m_stats.targetAllocations;
    return t;
}

void GlBackend::freeTarget(RenderTarget& t) {
    if (!t.colour.empty()) m_gl.DeleteTextures(GLsizei(t.colour.size()), t.colour.data());
    if (t.depth) m_gl.DeleteTextures(1, &t.depth);
    if (t.fbo) m_gl.DeleteFramebuffers(1, &t.fbo);
    t = {};
}

void GlBackend::resize(const FrameLayout& l) {
    if (l == m_layout) return;
    m_layout = l;
    for (RenderTarget* t :
         {&m_gbufferTarget, &m_lit, &m_postA, &m_postB, &m_eyeLeft, &m_eyeRight, &m_final, &m_scratch})
        freeTarget(*t);
    const int w = l.eyeWidth, h = l.eyeHeight;
    const std::array<GLenum, 3> hdr{GL_RGBA16F, GL_RGBA, GL_HALF_FLOAT}, ldr{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE};
    m_gbufferTarget = makeTarget(w, h, {hdr, ldr, ldr, ldr}, true);
    m_lit = makeTarget(w, h, {hdr}, false);
    m_postA = makeTarget(w, h, {hdr}, false);
    m_postB = makeTarget(w, h, {hdr}, false);
    m_scratch = makeTarget(w, h, {ldr}, false);
    if (l.eyes == 2) {
        m_eyeLeft = makeTarget(w, h, {ldr}, false);
        m_eyeRight = makeTarget(w, h, {ldr}, false);
    }
    m_final = makeTarget(l.outputWidth, l.outputHeight, {ldr}, false);
}

RenderTarget& GlBackend::target(Target t) {
    switch (t) {
    case Target::GBuffer:
        return m_gbufferTarget;
    case Target::Lit:
        return m_lit;
    case Target::PostA:
        return m_postA;
    case Target::PostB:
        return m_postB;
    case Target::EyeLeft:
        return m_eyeLeft;
    case Target::EyeRight:
        return m_eyeRight;
    case Target::Final:
        return m_final;
    case Target::None:
        break;
    }
    throw std::logic_error("render::GlBackend: no target");
}

void GlBackend::createMesh(size_t index, const RenderMesh& mesh) {
    if (m_meshes.size() <= index) m_meshes.resize(index + 1);
    GpuMesh& g = m_meshes[index];
    g.vertices = mesh.vertexCount();
    g.indices = mesh.indices.size();
    g.drawIndices = g.indices;
    m_gl.GenVertexArrays(1, &g.vao);
    m_gl.BindVertexArray(g.vao);
    auto buffer = [&](GLuint& b, size_t bytes, GLenum usage) {
        m_gl.GenBuffers(1, &b);
        m_gl.BindBuffer(GL_ARRAY_BUFFER, b);
        m_gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(bytes), nullptr, usage);
        ++m_stats.bufferAllocations;
    };
    const size_t v = g.vertices;
    buffer(g.position, v * 12, GL_DYNAMIC_DRAW);
    m_gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    buffer(g.previous, v * 12, GL_DYNAMIC_DRAW);
    m_gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    buffer(g.normal, v * 12, GL_DYNAMIC_DRAW);
    m_gl.VertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    buffer(g.heat, v * 4, GL_DYNAMIC_DRAW);
    m_gl.VertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, 0, nullptr);
    buffer(g.attributes, v * kAttributeBytes, GL_STATIC_DRAW); // rest xyz, thickness, samples, overlay rgba, uv
    m_gl.VertexAttribPointer(4, 4, GL_FLOAT, GL_FALSE, kAttributeBytes, nullptr);
    m_gl.VertexAttribPointer(5, 1, GL_FLOAT, GL_FALSE, kAttributeBytes, reinterpret_cast<const void*>(16));
    m_gl.VertexAttribPointer(6, 4, GL_FLOAT, GL_FALSE, kAttributeBytes, reinterpret_cast<const void*>(20));
    m_gl.VertexAttribPointer(7, 2, GL_FLOAT, GL_FALSE, kAttributeBytes, reinterpret_cast<const void*>(36));
    for (GLuint a = 0; a < 8; ++a)
        m_gl.EnableVertexAttribArray(a);
    m_gl.GenBuffers(1, &g.index);
    m_gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.index);
    m_gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(g.indices * 4), mesh.indices.data(), GL_DYNAMIC_DRAW);
    ++m_stats.bufferAllocations;
    m_gl.BindVertexArray(0);
    // First frame: previous positions = current.
    m_gl.BindBuffer(GL_ARRAY_BUFFER, g.previous);
    m_gl.BufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(v * 12), mesh.positions.data());
}

void GlBackend::updateFaceMask(size_t index, const RenderMesh& mesh) {
    GpuMesh& g = m_meshes.at(index);
    if (mesh.indices.size() != g.indices || !g.vao) return; // the Renderer never lets this happen
    mesh.drawnIndicesInto(m_maskScratch);
    g.drawIndices = m_maskScratch.size();
    m_gl.BindVertexArray(g.vao); // the element buffer binding belongs to the VAO
    m_gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.index);
    if (!m_maskScratch.empty())
        m_gl.BufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, GLsizeiptr(m_maskScratch.size() * 4), m_maskScratch.data());
    m_gl.BindVertexArray(0);
    ++m_stats.bufferUpdates;
}

void GlBackend::updateMesh(size_t index, const RenderMesh& mesh, bool staticChanged) {
    GpuMesh& g = m_meshes.at(index);
    if (mesh.vertexCount() != g.vertices) return; // the Renderer never lets this happen
    const size_t v = g.vertices;
    m_gl.BindBuffer(GL_COPY_READ_BUFFER, g.position);
    m_gl.BindBuffer(GL_COPY_WRITE_BUFFER, g.previous);
    m_gl.CopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, 0, 0, GLsizeiptr(v * 12));
    auto write = [&](GLuint b, const void* data, size_t bytes) {
        m_gl.BindBuffer(GL_ARRAY_BUFFER, b);
        m_gl.BufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(bytes), data);
        ++m_stats.bufferUpdates;
    };
    write(g.position, mesh.positions.data(), v * 12);
    write(g.normal, mesh.normals.data(), v * 12);
    write(g.heat, mesh.heat.data(), v * 4);
    if (staticChanged) {
        const bool overlay = mesh.overlay.size() == 4 * v;
        const bool uv = mesh.uv.size() == 2 * v;
        std::vector<float> attr(v * kAttributeFloats, 0.0f);
        for (size_t i = 0; i < v; ++i) {
            float* a = &attr[kAttributeFloats * i];
            a[0] = mesh.rest[3 * i + 0];
            a[1] = mesh.rest[3 * i + 1];
            a[2] = mesh.rest[3 * i + 2];
            a[3] = mesh.thickness[i];
            a[4] = mesh.sampleMap[i];
            if (overlay)
                for (int c = 0; c < 4; ++c)
                    a[5 + c] = mesh.overlay[4 * i + c];
            if (uv) {
                a[9] = mesh.uv[2 * i];
                a[10] = mesh.uv[2 * i + 1];
            }
        }
        write(g.attributes, attr.data(), attr.size() * 4);
        if (g.thicknessMap) {
            m_gl.DeleteTextures(1, &g.thicknessMap);
            g.thicknessMap = 0;
        }
        const Image& tm = mesh.thicknessMap;
        if (uv && !tm.empty() && tm.rgba.size() == size_t(tm.width) * size_t(tm.height) * 4) {
            std::vector<uint8_t> scratch;
            g.thicknessMap = uploadTexture(tm, false, scratch);
        }
    }
}

void GlBackend::bindTexture(Program& p, const char* uniform, int unit, GLuint texture) {
    m_gl.ActiveTexture(GLenum(GL_TEXTURE0 + unit));
    m_gl.BindTexture(GL_TEXTURE_2D, texture);
    p.set(uniform, unit);
}

void GlBackend::beginFullscreen(Program& p, const PassDesc& pass) {
    RenderTarget& out = target(pass.output);
    m_gl.BindFramebuffer(GL_FRAMEBUFFER, out.fbo);
    m_gl.Viewport(pass.viewport.x, pass.viewport.y, pass.viewport.width, pass.viewport.height);
    m_gl.Disable(GL_DEPTH_TEST);
    m_gl.Disable(GL_CULL_FACE);
    m_gl.Disable(GL_POLYGON_OFFSET_FILL);
    m_gl.DepthMask(GL_FALSE);
    p.use();
    m_gl.BindVertexArray(m_emptyVao);
}

void GlBackend::runPass(const PassDesc& pass, const PassContext& ctx) {
    ++m_stats.passesRun;
    switch (pass.kind) {
    case PassKind::GBuffer:
        gbufferPass(pass, ctx);
        break;
    case PassKind::Lighting:
        lightingPass(pass, ctx);
        break;
    case PassKind::Output:
        outputPass(pass);
        break;
    case PassKind::StereoCompose:
        composePass(pass);
        break;
    default:
        postPass(pass, ctx);
        break;
    }
}

void GlBackend::gbufferPass(const PassDesc& pass, const PassContext& ctx) {
    RenderTarget& t = m_gbufferTarget;
    m_gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    m_gl.Viewport(0, 0, t.width, t.height);
    m_gl.DepthMask(GL_TRUE);
    m_gl.Enable(GL_DEPTH_TEST);
    m_gl.DepthFunc(GL_LESS);
    const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
    for (int i = 0; i < 4; ++i)
        m_gl.ClearBufferfv(GL_COLOR, i, zero);
    m_gl.ClearBufferfv(GL_DEPTH, 0, &one);
    Program& p = *m_gbuffer;
    p.use();
    p.set("uViewProj", ctx.eye.viewProjection);
    p.set("uPrevViewProj", ctx.previousEye.viewProjection);
    p.set("uView", ctx.eye.view);
    p.set("uThicknessRange", kThicknessRange);
    m_gl.FrontFace(GL_CCW);
    const auto& meshes = ctx.view.meshes();
    for (size_t i = 0; i < meshes.size() && i < m_meshes.size(); ++i) {
        const RenderMesh& m = meshes[i];
        const GpuMesh& g = m_meshes[i];
        if (!m.visible || !g.vao || m.material >= ctx.view.materials().size()) continue;
        const TissueMaterial& mat = ctx.view.materials()[m.material];
        p.set("uMaterialId", float(std::min<uint32_t>(m.material, kMaxMaterials - 1)));
        p.set("uSurfaceColour", mat.surface.colour);
        p.set("uGranularColour", mat.granular.colour);
        p.set("uConnectiveColour", mat.connective.colour);
        p.set("uSubmucosaColour", mat.submucosa.colour);
        m_gl.Uniform4f(p.loc("uLayerWeights"), mat.surface.weight, mat.granular.weight, mat.connective.weight,
                       mat.submucosa.weight);
        m_gl.Uniform4f(p.loc("uLayerFrequency"), mat.surface.frequency, mat.granular.frequency,
                       mat.connective.frequency, mat.submucosa.frequency);
        p.set("uFibreAxis", Eigen::Vector3f(mat.fibreAxis.normalized()));
        p.set("uRoughness", mat.roughness);
        p.set("uGranularRoughness", mat.granularRoughness);
        p.set("uMetallic", mat.metallic);
        p.set("uReflection", mat.reflection);
        p.set("uFlags", float(mat.flags));
        p.set("uDoubleSided", m.doubleSided ? 1 : 0);
        p.set("uScreenDoor", m.translucent ? 1 : 0);
        const MaterialTextures& tex = texturesOf(m.material, mat);
        p.set("uMapMask", tex.mask);
        p.set("uHasThicknessMap", g.thicknessMap ? 1 : 0);
        if (g.thicknessMap) bindTexture(p, "uThicknessMap", 4, g.thicknessMap);
        if (g.thicknessMap && !tex.mask) p.set("uHasUv", 1);
        if (tex.mask) {
            static const char* const kSamplers[4] = {"uDiffuseMap", "uRoughnessMap", "uMetallicMap", "uNormalMap"};
            for (int k = 0; k < 4; ++k)
                if (tex.texture[k]) bindTexture(p, kSamplers[k], k, tex.texture[k]);
            p.set("uHasUv", m.uv.size() == 2 * m.vertexCount() && !m.uv.empty() ? 1 : 0);
            p.set("uTilesPerMetre", mat.maps->tilesPerMetre);
            p.set("uNormalStrength", mat.maps->normalStrength);
            ++m_stats.mappedDraws;
        }
        if (m.doubleSided)
            m_gl.Disable(GL_CULL_FACE);
        else {
            m_gl.Enable(GL_CULL_FACE);
            m_gl.CullFace(GL_BACK);
        }
        if (m.drawOnTop) {
            m_gl.Enable(GL_POLYGON_OFFSET_FILL);
            m_gl.PolygonOffset(-2.0f, -4.0f);
        } else
            m_gl.Disable(GL_POLYGON_OFFSET_FILL);
        if (g.drawIndices == 0) continue; // every face masked out
        m_gl.BindVertexArray(g.vao);
        m_gl.DrawElements(GL_TRIANGLES, GLsizei(g.drawIndices), GL_UNSIGNED_INT, nullptr);
        ++m_stats.drawCalls;
    }
    m_gl.BindVertexArray(0);
    m_gl.Disable(GL_POLYGON_OFFSET_FILL);
    (void)pass;
}

void GlBackend::lightingPass(const PassDesc& pass, const PassContext& ctx) {
    Program& p = *m_lighting;
    beginFullscreen(p, pass);
    bindTexture(p, "uG0", 0, m_gbufferTarget.colour[0]);
    bindTexture(p, "uG1", 1, m_gbufferTarget.colour[1]);
    bindTexture(p, "uG2", 2, m_gbufferTarget.colour[2]);
    bindTexture(p, "uG3", 3, m_gbufferTarget.colour[3]);
    bindTexture(p, "uDepth", 4, m_gbufferTarget.depth);
    const RenderSettings& s = ctx.settings;
    p.set("uInvViewProj", ctx.eye.inverseViewProjection);
    p.set("uEyePos", ctx.eye.position);
    p.set("uLightCenter", ctx.light.center);
    p.set("uLightNormal", ctx.light.normal);
    p.set("uLightHalfU", ctx.light.halfU);
    p.set("uLightHalfV", ctx.light.halfV);
    p.set("uLightRadiance", ctx.light.radiance);
    p.set("uLightArea", ctx.light.area);
    p.set("uMode", int(s.sampling.mode));
    p.set("uUniformSamples", s.sampling.uniformSamples);
    p.set("uReferenceSamples", s.sampling.referenceSamples);
    const int bands = int(std::min<size_t>(s.sampling.bands.size(), 8));
    float bandMax[8] = {};
    int bandSamples[8] = {};
    for (int b = 0; b < bands; ++b) {
        bandMax[b] = std::min(s.sampling.bands[b].maxDistance, 1e30f);
        bandSamples[b] = s.sampling.bands[b].samples;
    }
    p.set("uBandCount", bands);
    m_gl.Uniform1fv(p.loc("uBandMax"), 8, bandMax);
    m_gl.Uniform1iv(p.loc("uBandSamples"), 8, bandSamples);
    p.set("uUseCone", s.sampling.specularCone && s.sampling.mode != SampleMode::Reference ? 1 : 0);
    p.set("uConeCutoff", s.sampling.coneCutoff);
    p.set("uSubsurface", s.subsurface ? 1 : 0);
    p.set("uAmbient", s.ambient);
    p.set("uBackground", s.background);
    p.set("uEnvironment", Eigen::Vector3f(0.25f, 0.12f, 0.10f));
    p.set("uThicknessRange", kThicknessRange);
    float ksss[kMaxMaterials] = {}, f0[kMaxMaterials] = {};
    float sssColour[3 * kMaxMaterials] = {}, sigma[3 * kMaxMaterials] = {};
    const auto& mats = ctx.view.materials();
    for (size_t i = 0; i < mats.size() && i < size_t(kMaxMaterials); ++i) {
        ksss[i] = mats[i].sssWeight;
        f0[i] = mats[i].f0;
        for (int c = 0; c < 3; ++c) {
            sssColour[3 * i + c] = mats[i].sssColour[c];
            sigma[3 * i + c] = mats[i].sigma[c];
        }
    }
    m_gl.Uniform1fv(p.loc("uKsss"), kMaxMaterials, ksss);
    m_gl.Uniform1fv(p.loc("uF0"), kMaxMaterials, f0);
    m_gl.Uniform3fv(p.loc("uSssColour"), kMaxMaterials, sssColour);
    m_gl.Uniform3fv(p.loc("uSigma"), kMaxMaterials, sigma);
    m_gl.DrawArrays(GL_TRIANGLES, 0, 3);
}

void GlBackend::postPass(const PassDesc& pass, const PassContext& ctx) {
    Program& p = *m_post.at(int(pass.kind));
    beginFullscreen(p, pass);
    bindTexture(p, "uInput", 0, targetTexture(pass.input));
    const PostSettings& s = ctx.settings.post;
    const Eigen::Vector2f texel(1.0f / float(pass.viewport.width), 1.0f / float(pass.viewport.height));
    switch (pass.kind) {
    case PassKind::DepthOfField:
        bindTexture(p, "uG0", 1, m_gbufferTarget.colour[0]);
        p.set("uTexel", texel);
        p.set("uFocusDistance", s.depthOfField.focusDistance);
        p.set("uFocusRange", s.depthOfField.focusRange);
        p.set("uBlurPerMetre", s.depthOfField.blurPerMetre);
        p.set("uMaxRadius", s.depthOfField.maxRadiusPx);
        break;
    case PassKind::ChromaticAberration:
        p.set("uStrength", s.chromaticAberration.strength);
        break;
    case PassKind::ToneMapping:
        p.set("uExposure", s.toneMapping.exposure);
        p.set("uOperator", int(s.toneMapping.op));
        break;
    case PassKind::ColourCurve: {
        float pts[16] = {};
        const int n = int(std::min<size_t>(s.colourCurve.points.size(), 8));
        for (int i = 0; i < n; ++i) {
            pts[2 * i] = s.colourCurve.points[i].x();
            pts[2 * i + 1] = s.colourCurve.points[i].y();
        }
        m_gl.Uniform2fv(p.loc("uPoints"), 8, pts);
        p.set("uCount", n);
        p.set("uGain", s.colourCurve.gain);
        break;
    }
    case PassKind::Sharpen:
        p.set("uTexel", texel);
        p.set("uAmount", s.sharpen.amount);
        break;
    case PassKind::Noise: {
        p.set("uAmount", s.noise.amount);
        const uint32_t seed = s.noise.seed + (s.noise.animate ? uint32_t(ctx.frameIndex) * 7919u : 0u);
        m_gl.Uniform1i(p.loc("uSeed"), GLint(seed & 0x7fffffff));
        break;
    }
    case PassKind::RadialMask:
        p.set("uAspect", float(pass.viewport.width) / float(pass.viewport.height));
        p.set("uInner", s.radialMask.inner);
        p.set("uOuter", s.radialMask.outer);
        p.set("uColour", s.radialMask.colour);
        break;
    default:
        break;
    }
    m_gl.DrawArrays(GL_TRIANGLES, 0, 3);
}

void GlBackend::outputPass(const PassDesc& pass) {
    Program& p = *m_output;
    beginFullscreen(p, pass);
    bindTexture(p, "uInput", 0, targetTexture(pass.input));
    m_gl.DrawArrays(GL_TRIANGLES, 0, 3);
}

void GlBackend::composePass(const PassDesc& pass) {
    Program& p = *m_anaglyph;
    beginFullscreen(p, pass);
    bindTexture(p, "uLeft", 0, m_eyeLeft.colour.at(0));
    bindTexture(p, "uRight", 1, m_eyeRight.colour.at(0));
    m_gl.DrawArrays(GL_TRIANGLES, 0, 3);
}

Image GlBackend::readPixels(ImageStage stage) {
    RenderTarget* src = &m_final;
    if (stage == ImageStage::Unprocessed) {
        // The lit image through the same output encoding, into a scratch target.
        PassDesc pass{PassKind::Output, 0, Target::Lit, Target::None, {0, 0, m_lit.width, m_lit.height}};
        Program& p = *m_output;
        m_gl.BindFramebuffer(GL_FRAMEBUFFER, m_scratch.fbo);
        m_gl.Viewport(0, 0, m_scratch.width, m_scratch.height);
        m_gl.Disable(GL_DEPTH_TEST);
        m_gl.Disable(GL_CULL_FACE);
        p.use();
        m_gl.BindVertexArray(m_emptyVao);
        bindTexture(p, "uInput", 0, m_lit.colour.at(0));
        m_gl.DrawArrays(GL_TRIANGLES, 0, 3);
        (void)pass;
        src = &m_scratch;
    }
    Image img;
    img.width = src->width;
    img.height = src->height;
    img.rgba.resize(size_t(img.width) * img.height * 4);
    if (!src->fbo) return img;
    m_gl.BindFramebuffer(GL_READ_FRAMEBUFFER, src->fbo);
    m_gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    m_gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    std::vector<uint8_t> raw(img.rgba.size());
    m_gl.ReadPixels(0, 0, img.width, img.height, GL_RGBA, GL_UNSIGNED_BYTE, raw.data());
    const size_t row = size_t(img.width) * 4;
    for (int y = 0; y < img.height; ++y)
        std::memcpy(&img.rgba[size_t(y) * row], &raw[size_t(img.height - 1 - y) * row], row);
    return img;
}

std::vector<float> GlBackend::readDepth() {
    const int w = m_gbufferTarget.width, h = m_gbufferTarget.height;
    std::vector<float> raw(size_t(w) * h), out(raw.size());
    if (!m_gbufferTarget.fbo) return out;
    m_gl.BindFramebuffer(GL_READ_FRAMEBUFFER, m_gbufferTarget.fbo);
    m_gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    m_gl.ReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, raw.data());
    for (int y = 0; y < h; ++y)
        std::memcpy(&out[size_t(y) * w], &raw[size_t(h - 1 - y) * w], size_t(w) * sizeof(float));
    return out;
}

void GlBackend::present(uint32_t framebuffer, int width, int height) {
    m_gl.BindFramebuffer(GL_READ_FRAMEBUFFER, m_final.fbo);
    m_gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    m_gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer);
    m_gl.BlitFramebuffer(0, 0, m_final.width, m_final.height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    m_gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
}

/// The backend keeps its Api by reference; this owner keeps both alive together.
class OwningGlBackend final : public Backend {
public:
    std::unique_ptr<gl::Api> api;
    std::unique_ptr<GlBackend> impl;
    const char* name() const override { return impl->name(); }
    void resize(const FrameLayout& l) override { impl->resize(l); }
    void createMesh(size_t i, const RenderMesh& m) override { impl->createMesh(i, m); }
    void updateMesh(size_t i, const RenderMesh& m, bool s) override { impl->updateMesh(i, m, s); }
    void updateFaceMask(size_t i, const RenderMesh& m) override { impl->updateFaceMask(i, m); }
    void runPass(const PassDesc& p, const PassContext& c) override { impl->runPass(p, c); }
    void finish() override { impl->finish(); }
    Image readPixels(ImageStage s) override { return impl->readPixels(s); }
    std::vector<float> readDepth() override { return impl->readDepth(); }
    void present(uint32_t f, int w, int h) override { impl->present(f, w, h); }
    BackendStats stats() const override { return impl->stats(); }
    std::string deviceName() const override { return impl->deviceName(); }
    ~OwningGlBackend() override { impl.reset(); }
};

} // namespace

std::unique_ptr<Backend> createGlBackend(GlProcLoader loader, void* user, std::string* whyNot) {
    auto owner = std::make_unique<OwningGlBackend>();
    owner->api = std::make_unique<gl::Api>();
    std::string missing;
    if (!owner->api->load(loader, user, &missing)) {
        if (whyNot) *whyNot = "OpenGL entry point " + missing + " is missing";
        return nullptr;
    }
    owner->impl = std::make_unique<GlBackend>(*owner->api);
    if (!owner->impl->init(whyNot)) return nullptr;
    return owner;
}

} // namespace viscera::render
