#pragma once
/// \file Renderer.hpp
/// Batched forward renderer: lit, textured, shadowed meshes drawn with one multi-draw per texture (object
/// transforms come from a buffer texture indexed per vertex; cut faces in batches of their own), an instanced
/// particle pass, debug lines and a skybox (the scene's six images on a cube, or a procedural sky). Two
/// quality levels: per-pixel lighting with shadows (GPUs), per-vertex lighting without (software GL).

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "Math.hpp"
#include "rubble/rubble.hpp"

namespace demo {

/// A particle: a camera-facing square.
struct Particle {
    V3 pos;                    ///< centre
    float size = 0.2f;         ///< edge length in metres
    float r = 1, g = 1, b = 1; ///< colour
    float a = 1;               ///< opacity (additive particles: brightness)
};

/// How much the renderer does per pixel; chosen from GL_RENDERER by forRenderer.
struct RenderQuality {
    bool software = false;      ///< a software rasteriser (llvmpipe, softpipe, swrast)
    bool shadows = true;        ///< shadow map
    int shadowSize = 1024;      ///< shadow map edge in texels
    bool pixelLighting = true;  ///< per-pixel sun, specular and shadows (else per-vertex sun, no specular)
    bool trilinear = true;      ///< mipmaps blended (else nearest mip level, bilinear)
    bool nearestTexels = false; ///< nearest texel of the nearest mip level, sky included (no filtering)
    float minScale = 1.0f;      ///< smallest internal resolution scale dynamic resolution may use (1 = off)
    float chipPixels = 1.5f;    ///< meshes whose bounding sphere projects below this radius (px) are chips
    int meshBudget = 8000;      ///< meshes drawn with their triangles a frame; the smallest on screen beyond
                                ///< it are chips
    /// GPUs: everything on; software GL: shadows off, per-vertex lighting, nearest texels, fewer dust
    /// particles, more and larger chips.
    static RenderQuality forRenderer(const std::string& glRenderer);
    /// "software" or "gpu".
    const char* name() const { return software ? "software" : "gpu"; }
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
    /// Compiles shaders and creates buffers for the given quality. Returns false with a message on failure.
    bool init(const RenderQuality& quality, std::string& error);
    /// The quality chosen at init.
    const RenderQuality& quality() const { return quality_; }
    /// Frees GL objects.
    void shutdown();

    /// Loads a PNG/JPG texture (stb_image); when missing, warns and returns a procedural stand-in of the
    /// given kind ("grid", "concrete", "metal", "interior"). Cached by path.
    int loadTexture(const std::filesystem::path& path, const std::string& kind,
                    std::vector<std::string>& warnings);
    /// The procedural cut-face texture of a material preset (concrete, brick, stone, wood, glass, steel;
    /// others look like concrete), made once.
    int materialInterior(const std::string& material);
    /// Uses the image at path for cut faces (kInteriorMaterial); false (procedural kept) when unreadable.
    bool setInteriorTexture(const std::filesystem::path& path);
    /// A procedural texture of the given kind.
    int proceduralTexture(const std::string& kind);
    /// Sets the skybox from six images (top, bottom, left, right, front, back). Missing images: procedural
    /// sky.
    void setSkybox(const std::array<std::filesystem::path, 6>& faces, std::vector<std::string>& warnings);

    /// Uploads a mesh to the batch of its texture; returns its id. uvScale multiplies existing UVs.
    int addMesh(const rubble::Mesh& mesh, int texture, float r = 1, float g = 1, float b = 1,
                int interiorTexture = -1);
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
    /// Meshes left out of the last render() by frustum culling.
    int culled() const { return culled_; }
    /// Meshes drawn with their triangles in the last render().
    int meshesDrawn() const { return meshesDrawn_; }
    /// Meshes drawn as chips (one opaque square each, the level of detail of distant small pieces).
    int chipsDrawn() const { return chipsDrawn_; }
    /// Shadows on/off.
    bool shadows = true;
    /// Sun direction (pointing from the sun).
    V3 sunDir = norm(V3{-0.45f, -0.8f, -0.35f});

private:
    struct Batch {
        GLuint vao = 0, vbo = 0;
        int texture = 0;       ///< texture of exterior batches
        bool interior = false; ///< cut faces: drawn with the interior texture
        std::vector<float> cpu;
        size_t gpuCapacity = 0;
        size_t uploaded = 0; ///< floats of cpu already in the GPU buffer (appends upload only the rest)
        int dead = 0;
        std::vector<GLint> firsts;         ///< ranges drawn this frame (inside the view frustum)
        std::vector<GLsizei> counts;       ///< their vertex counts
        std::vector<GLint> shadowFirsts;   ///< ranges casting shadows (every queued mesh)
        std::vector<GLsizei> shadowCounts; ///< their vertex counts
        V3 average{0.5f, 0.5f, 0.5f};      ///< mean colour of the texture (chips)
        int drawn = 0;                     ///< meshes drawn from it this frame (fullest batches first)
    };
    /// A mesh: its exterior triangles (range 0) and its cut faces (range 1), each in its own batch.
    struct MeshRec {
        int batch[2] = {-1, -1};
        int first[2] = {0, 0};
        int count[2] = {0, 0};
        bool alive = false;
        V3 centre;        ///< bounding sphere in mesh coordinates
        float radius = 0; ///< bounding sphere radius
        V3 chip;          ///< colour as a chip: texture mean, tint and average light
    };
    /// A visible mesh this frame: id and projected bounding radius in pixels.
    struct Visible {
        int id;
        float pixels;
    };
    int batchFor(int texture, bool interior);
    std::vector<int> batchOrder_; ///< batches by meshes drawn, most first: debris before the ground it hides
    void bakeSkyCube();
    void bakeProceduralSky();
    void uploadBatch(Batch& b);
    void compact(Batch& b, int batchIndex);
    void drawBatches(bool depthOnly, GLuint program);
    void cullAndBatch(const M4& viewProj, float pixelsPerRadian, bool lod);
    static void mergeRanges(std::vector<GLint>& firsts, std::vector<GLsizei>& counts);
    void applyFilter(GLenum target);

    RenderQuality quality_;
    GLuint meshProg_ = 0, depthProg_ = 0, skyProg_ = 0, particleProg_ = 0, lineProg_ = 0;
    GLuint slotBuf_ = 0, slotTex_ = 0;
    size_t slotCapacity_ = 0;
    std::vector<float> slotData_;
    int maxSlotUsed_ = 0;
    std::vector<Batch> batches_;
    std::vector<MeshRec> meshes_;
    std::vector<int> freeIds_;
    int liveMeshes_ = 0;
    std::vector<int> queued_; ///< meshes drawn this frame (drawMesh), culled in render()
    int culled_ = 0;
    int meshesDrawn_ = 0;
    int chipsDrawn_ = 0;
    std::vector<GLuint> textures_;
    std::vector<std::string> texturePaths_;
    GLuint skyFaces_[6] = {}; ///< the scene's six sky images (0: procedural sky)
    GLuint skyVao_ = 0, skyVbo_ = 0;
    int skyVertices_ = 0;
    GLuint cubeVao_ = 0, cubeVbo_ = 0;
    GLuint emptyVao_ = 0;
    GLuint particleVao_ = 0, particleQuad_ = 0, particleInst_ = 0;
    std::vector<float> dust_, sparks_;
    GLuint lineVao_ = 0, lineVbo_ = 0;
    GLuint chipProg_ = 0, chipVao_ = 0, chipVbo_ = 0;
    std::vector<float> chips_;     ///< per chip: position, diameter in pixels, colour
    std::vector<Visible> visible_; ///< meshes inside the frustum this frame

    std::vector<float> lines_;
    GLuint shadowFbo_ = 0, shadowTex_ = 0;
    int shadowSize_ = 1024;
    int interiorTex_ = 0;
    int drawCalls_ = 0;
    long long triangles_ = 0;
};

} // namespace demo
