#pragma once
/// \file Renderer.hpp
/// Batched forward renderer: lit, textured, shadowed meshes drawn with one multi-draw per texture (object
/// transforms come from a buffer texture indexed per vertex), an instanced particle pass, debug lines and a
/// skybox (cube map from the scene's six images, or a procedural sky).

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "Math.hpp"
#include "rubble/Mesh.hpp"

namespace demo {

/// A particle: a camera-facing square.
struct Particle {
    V3 pos;                    ///< centre
    float size = 0.2f;         ///< edge length in metres
    float r = 1, g = 1, b = 1; ///< colour
    float a = 1;               ///< opacity (additive particles: brightness)
};

/// Camera and light for one frame.
struct FrameView {
    M4 view;        ///< view matrix
    M4 proj;        ///< projection matrix
    V3 eye;         ///< camera position
    V3 focus;       ///< point the shadow map is centred on
    int width = 1;  ///< viewport width
    int height = 1; ///< viewport height
    GLuint fbo = 0; ///< target framebuffer
};

/// The renderer. All calls need the GL context current.
class Renderer {
public:
    /// Compiles shaders and creates buffers. Returns false with a message on failure.
    bool init(std::string& error);
    /// Frees GL objects.
    void shutdown();

    /// Loads a PNG/JPG texture (stb_image); when missing, warns and returns a procedural stand-in of the
    /// given kind ("grid", "concrete", "metal", "interior"). Cached by path.
    int loadTexture(const std::filesystem::path& path, const std::string& kind,
                    std::vector<std::string>& warnings);
    /// Uses the image at path for cut faces (kInteriorMaterial); false (procedural kept) when unreadable.
    bool setInteriorTexture(const std::filesystem::path& path);
    /// A procedural texture of the given kind.
    int proceduralTexture(const std::string& kind);
    /// Sets the skybox from six images (top, bottom, left, right, front, back). Missing images: procedural
    /// sky.
    void setSkybox(const std::array<std::filesystem::path, 6>& faces, std::vector<std::string>& warnings);

    /// Uploads a mesh to the batch of its texture; returns its id. uvScale multiplies existing UVs.
    int addMesh(const rubble::Mesh& mesh, int texture, float r = 1, float g = 1, float b = 1);
    /// Frees a mesh id.
    void removeMesh(int id);
    /// Number of live meshes.
    int meshCount() const { return liveMeshes_; }

    /// Starts collecting a frame.
    void beginFrame();
    /// Draws mesh id with a rigid transform; heat in [0,1] makes interior faces glow; fade in [0,1] blends
    /// in.
    void drawMesh(int id, const M4& model, float heat = 0, float fade = 1);
    /// Adds a particle (alpha-blended dust when additive=false, glowing spark when true).
    void addParticle(const Particle& p, bool additive);
    /// Adds a debug line.
    void addLine(const V3& a, const V3& b, float r, float g, float bl);
    /// Renders everything collected this frame.
    void render(const FrameView& view);

    /// Draw calls issued in the last render().
    int drawCalls() const { return drawCalls_; }
    /// Triangles drawn in the last render().
    long long triangles() const { return triangles_; }
    /// Shadows on/off.
    bool shadows = true;
    /// Sun direction (pointing from the sun).
    V3 sunDir = norm(V3{-0.45f, -0.8f, -0.35f});

private:
    struct Batch {
        GLuint vao = 0, vbo = 0;
        int texture = 0;
        std::vector<float> cpu;
        size_t gpuCapacity = 0;
        bool dirty = false;
        int dead = 0;
        std::vector<GLint> firsts;
        std::vector<GLsizei> counts;
    };
    struct MeshRec {
        int batch = -1;
        int first = 0;
        int count = 0;
        bool alive = false;
    };
    int batchFor(int texture);
    void bakeProceduralSky();
    void uploadBatch(Batch& b);
    void compact(Batch& b, int batchIndex);
    void drawBatches(bool depthOnly);

    GLuint meshProg_ = 0, depthProg_ = 0, skyProg_ = 0, particleProg_ = 0, lineProg_ = 0;
    GLuint slotBuf_ = 0, slotTex_ = 0;
    size_t slotCapacity_ = 0;
    std::vector<float> slotData_;
    int maxSlotUsed_ = 0;
    std::vector<Batch> batches_;
    std::vector<MeshRec> meshes_;
    std::vector<int> freeIds_;
    int liveMeshes_ = 0;
    std::vector<GLuint> textures_;
    std::vector<std::string> texturePaths_;
    GLuint skyCube_ = 0;
    GLuint skyVao_ = 0, skyVbo_ = 0;
    int skyVertices_ = 0;
    GLuint emptyVao_ = 0;
    GLuint particleVao_ = 0, particleQuad_ = 0, particleInst_ = 0;
    std::vector<float> dust_, sparks_;
    GLuint lineVao_ = 0, lineVbo_ = 0;
    std::vector<float> lines_;
    GLuint shadowFbo_ = 0, shadowTex_ = 0;
    int shadowSize_ = 1024;
    int interiorTex_ = 0;
    int drawCalls_ = 0;
    long long triangles_ = 0;
};

} // namespace demo
