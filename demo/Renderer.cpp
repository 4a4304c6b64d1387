#include "Renderer.hpp"

#include "GlProgram.hpp"

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

namespace demo {

namespace {

constexpr int kFloatsPerVertex = 9; // pos3 normal3 uv2 slot
constexpr int kTexelsPerSlot = 6;   // mat4 columns, (heat, fade), tint

// Per-pixel lighting (GPUs): sun with specular and shadow map, hemisphere ambient, fog.
const char* kMeshVs = R"(#version 330 core
layout(location=0) in vec3 aPos;
layout(location=1) in vec3 aNormal;
layout(location=2) in vec2 aUv;
layout(location=3) in float aSlot;
uniform samplerBuffer uSlots;
uniform mat4 uViewProj;
uniform mat4 uLightVP;
out vec3 vWorld; out vec3 vNormal; out vec2 vUv; out vec2 vHeatFade; out vec3 vTint;
out vec4 vLight;
void main() {
    int b = int(aSlot + 0.5) * 6;
    mat4 M = mat4(texelFetch(uSlots, b), texelFetch(uSlots, b + 1), texelFetch(uSlots, b + 2), texelFetch(uSlots, b + 3));
    vHeatFade = texelFetch(uSlots, b + 4).xy;
    vTint = texelFetch(uSlots, b + 5).rgb;
    vec4 w = M * vec4(aPos, 1.0);
    vWorld = w.xyz;
    vNormal = mat3(M) * aNormal;
    vUv = aUv;
    vLight = uLightVP * w;
    gl_Position = uViewProj * w;
})";

const char* kMeshFs = R"(#version 330 core
in vec3 vWorld; in vec3 vNormal; in vec2 vUv; in vec2 vHeatFade; in vec3 vTint; in vec4 vLight;
uniform sampler2D uTex;
uniform sampler2DShadow uShadow;
uniform int uUseShadow;
uniform int uInterior;
uniform vec3 uSunDir;
uniform vec3 uCamPos;
uniform vec3 uFogColor;
out vec4 oColor;
float shadowAt() {
    if (uUseShadow == 0) return 1.0;
    vec3 p = vLight.xyz / vLight.w * 0.5 + 0.5;
    if (p.x <= 0.0 || p.x >= 1.0 || p.y <= 0.0 || p.y >= 1.0 || p.z >= 1.0) return 1.0;
    return texture(uShadow, vec3(p.xy, p.z - 0.002));
}
void main() {
    vec3 n = normalize(vNormal);
    if (!gl_FrontFacing) n = -n;
    vec3 t = texture(uTex, vUv).rgb;
    vec3 albedo = uInterior == 1 ? t * t * vec3(0.85, 0.78, 0.70) : t * t * vTint;
    vec3 L = -uSunDir;
    float ndl = max(dot(n, L), 0.0);
    float sh = ndl > 0.0 ? shadowAt() : 0.0;
    vec3 amb = mix(vec3(0.11, 0.094, 0.077), vec3(0.20, 0.25, 0.34), n.y * 0.5 + 0.5);
    vec3 V = normalize(uCamPos - vWorld);
    vec3 H = normalize(V + L);
    float s2 = max(dot(n, H), 0.0);
    s2 *= s2; s2 *= s2; s2 *= s2; s2 *= s2; s2 *= s2;
    vec3 sun = vec3(1.6, 1.49, 1.31);
    vec3 c = albedo * (amb + sun * (ndl * sh)) + sun * (s2 * 0.2 * ndl * sh);
    // fresh cuts: embers in the material's grain, white-hot cooling to dark red, fading to the lit interior
    float heat = vHeatFade.x * float(uInterior);
    vec3 ember = mix(vec3(0.9, 0.12, 0.02), vec3(1.7, 0.85, 0.35), heat);
    c += ember * (heat * heat) * (0.3 + 1.4 * dot(t, vec3(0.3, 0.5, 0.2)));
    vec3 dv = uCamPos - vWorld;
    float fog = 1.0 - exp(-dot(dv, dv) * 2.5e-6);
    c = mix(c, uFogColor * uFogColor, fog);
    c = c / (1.0 + c * 0.15);
    oColor = vec4(sqrt(c), vHeatFade.y);
})";

// Per-vertex lighting (software GL): the fragment shader samples one texture, multiplies and applies fog.
const char* kLiteVs = R"(#version 330 core
layout(location=0) in vec3 aPos;
layout(location=1) in vec3 aNormal;
layout(location=2) in vec2 aUv;
layout(location=3) in float aSlot;
uniform samplerBuffer uSlots;
uniform mat4 uViewProj;
uniform int uInterior;
uniform vec3 uSunDir;
uniform vec3 uCamPos;
out vec2 vUv; out vec3 vLit; out vec3 vGlow; out vec3 vDv; out float vFade;
void main() {
    int b = int(aSlot + 0.5) * 6;
    mat4 M = mat4(texelFetch(uSlots, b), texelFetch(uSlots, b + 1), texelFetch(uSlots, b + 2), texelFetch(uSlots, b + 3));
    vec2 heatFade = texelFetch(uSlots, b + 4).xy;
    vec3 tint = uInterior == 1 ? vec3(0.85, 0.78, 0.70) : texelFetch(uSlots, b + 5).rgb;
    vec4 w = M * vec4(aPos, 1.0);
    vec3 n = normalize(mat3(M) * aNormal);
    float ndl = max(dot(n, -uSunDir), 0.0);
    vec3 amb = mix(vec3(0.11, 0.094, 0.077), vec3(0.20, 0.25, 0.34), n.y * 0.5 + 0.5);
    // the per-pixel path's light, tone map and gamma folded into one factor on the texture's colour:
    // sqrt(t * t * L) = t * sqrt(L)
    vec3 L = tint * (amb + vec3(1.6, 1.49, 1.31) * ndl);
    vLit = sqrt(L / (1.0 + L * 0.15));
    float heat = heatFade.x * float(uInterior); // embers in the texture's grain, cooling to dark red
    vGlow = heat * mix(vec3(0.9, 0.2, 0.05), vec3(1.5, 0.9, 0.5), heat);
    vFade = heatFade.y;
    vDv = uCamPos - w.xyz;
    vUv = aUv;
    gl_Position = uViewProj * w;
})";

const char* kLiteFs = R"(#version 330 core
in vec2 vUv; in vec3 vLit; in vec3 vGlow; in vec3 vDv; in float vFade;
uniform sampler2D uTex;
uniform vec3 uFogColor;
out vec4 oColor;
void main() {
    vec3 c = texture(uTex, vUv).rgb * (vLit + vGlow);
    float x = dot(vDv, vDv) * 2.5e-6;
    oColor = vec4(mix(c, uFogColor, x / (1.0 + x)), vFade);
})";

const char* kDepthVs = R"(#version 330 core
layout(location=0) in vec3 aPos;
layout(location=3) in float aSlot;
uniform samplerBuffer uSlots;
uniform mat4 uViewProj;
void main() {
    int b = int(aSlot + 0.5) * 6;
    mat4 M = mat4(texelFetch(uSlots, b), texelFetch(uSlots, b + 1), texelFetch(uSlots, b + 2), texelFetch(uSlots, b + 3));
    gl_Position = uViewProj * M * vec4(aPos, 1.0);
})";

const char* kDepthFs = R"(#version 330 core
void main() {})";

const char* kSkyVs = R"(#version 330 core
layout(location=0) in vec3 aDir;
layout(location=1) in vec3 aColor; // procedural dome: colour; image cube: (u, v, layer)
uniform mat4 uViewProj;
out vec3 vColor;
void main() {
    vColor = aColor;
    gl_Position = (uViewProj * vec4(aDir, 1.0)).xyww;
})";

const char* kSkyFs = R"(#version 330 core
in vec3 vColor;
uniform sampler2D uFaces; // the face's image
uniform int uHasCube;
out vec4 oColor;
void main() {
    if (uHasCube == 0) { oColor = vec4(vColor, 1.0); return; }
    oColor = vec4(texture(uFaces, vColor.xy).rgb, 1.0);
})";

const char* kParticleVs = R"(#version 330 core
layout(location=0) in vec2 aCorner;
layout(location=1) in vec4 aPosSize;
layout(location=2) in vec4 aColor;
uniform mat4 uViewProj;
uniform vec3 uRight;
uniform vec3 uUp;
uniform float uMaxSize; // largest size per metre of depth (a cap on the screen share of one particle)
out vec2 vCorner; out vec4 vColor;
void main() {
    float depth = max((uViewProj * vec4(aPosSize.xyz, 1.0)).w, 0.1);
    float size = min(aPosSize.w, uMaxSize * depth);
    vec3 p = aPosSize.xyz + (uRight * aCorner.x + uUp * aCorner.y) * size;
    vCorner = aCorner * 2.0;
    vColor = aColor;
    gl_Position = uViewProj * vec4(p, 1.0);
})";

const char* kParticleFs = R"(#version 330 core
in vec2 vCorner; in vec4 vColor;
uniform int uAdditive;
out vec4 oColor;
void main() {
    // no discard and no pow: outside the disc the weight is 0 (blending leaves the pixel as it was)
    float k = max(1.0 - dot(vCorner, vCorner), 0.0);
    float f = uAdditive == 1 ? k * k : min(k * 8.0, 1.0) * (0.4 + 0.6 * k);
    oColor = vec4(vColor.rgb, vColor.a * f);
})";

// Chips: distant small pieces as opaque squares (points), lit and fogged per piece.
const char* kChipVs = R"(#version 330 core
layout(location=0) in vec4 aPosSize;
layout(location=1) in vec3 aColor;
uniform mat4 uViewProj;
uniform vec3 uCamPos;
uniform vec3 uFogColor;
out vec3 vColor;
void main() {
    vec3 dv = uCamPos - aPosSize.xyz;
    float x = dot(dv, dv) * 2.5e-6;
    vColor = mix(aColor, uFogColor, x / (1.0 + x));
    gl_PointSize = aPosSize.w;
    gl_Position = uViewProj * vec4(aPosSize.xyz, 1.0);
})";

const char* kChipFs = R"(#version 330 core
in vec3 vColor; out vec4 oColor;
void main() { oColor = vec4(vColor, 1.0); })";

const char* kLineVs = R"(#version 330 core
layout(location=0) in vec3 aPos;
layout(location=1) in vec3 aColor;
uniform mat4 uViewProj;
out vec3 vColor;
void main() { vColor = aColor; gl_Position = uViewProj * vec4(aPos, 1.0); })";

const char* kLineFs = R"(#version 330 core
in vec3 vColor; out vec4 oColor;
void main() { oColor = vec4(vColor, 1.0); })";

GLint loc(GLuint p, const char* name) {
    return glGetUniformLocation(p, name);
}

float hashNoise(int x, int y, int seed) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 374761393u +
                      static_cast<std::uint32_t>(y) * 668265263u +
                      static_cast<std::uint32_t>(seed) * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return static_cast<float>((h ^ (h >> 16)) & 0xFFFF) / 65535.0f;
}

float valueNoise(float x, float y, int period, int seed) {
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    auto h = [&](int a, int b) {
        return hashNoise(((a % period) + period) % period, ((b % period) + period) % period, seed);
    };
    const float sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
    const float a = h(x0, y0) + (h(x0 + 1, y0) - h(x0, y0)) * sx;
    const float b = h(x0, y0 + 1) + (h(x0 + 1, y0 + 1) - h(x0, y0 + 1)) * sx;
    return a + (b - a) * sy;
}

float fbm(float x, float y, int period, int seed) {
    float s = 0, amp = 0.5f;
    for (int o = 0; o < 5; ++o) {
        s += amp * valueNoise(x, y, period, seed + o);
        x *= 2;
        y *= 2;
        period *= 2;
        amp *= 0.5f;
    }
    return s;
}

GLuint uploadRgba(const unsigned char* data, int w, int h, const RenderQuality& q) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, data);
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER,
                    q.trilinear       ? GL_LINEAR_MIPMAP_LINEAR
                    : q.nearestTexels ? GL_NEAREST_MIPMAP_NEAREST
                                      : GL_LINEAR_MIPMAP_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, q.nearestTexels ? GL_NEAREST : GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    return t;
}

// A vertex array of interleaved float triples (position, then a second attribute) in a new buffer holding
// `data` (nothing yet when empty); leaves nothing bound.
void makeTripleArray(GLuint& vao, GLuint& vbo, const std::vector<float>& data) {
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    if (!data.empty())
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(),
                     GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glBindVertexArray(0);
}

} // namespace

RenderQuality RenderQuality::forRenderer(const std::string& glRenderer) {
    RenderQuality q;
    for (const char* soft : {"llvmpipe", "softpipe", "swrast", "Software Rasterizer"})
        if (glRenderer.find(soft) != std::string::npos)
            q.software = true;
    if (q.software) {
        q.shadows = false;
        q.pixelLighting = false;
        q.trilinear = false;
        q.nearestTexels = true; // about 4 of 30 CPU ms a frame at 1080p (docs/rendering.md)
        // Dynamic resolution stays off: with per-vertex lighting a pixel costs about what the upscale pass
        // costs per output pixel, so on llvmpipe 2/3 scale saved nothing (docs/rendering.md).
        q.minScale = 1.0f;
        // a vertex costs llvmpipe's main thread about 45 ns: small pieces become chips early
        q.chipPixels = 4.0f;
        q.meshBudget = 600;
    }
    return q;
}

bool Renderer::init(const RenderQuality& quality, std::string& error) {
    quality_ = quality;
    shadows = quality.shadows;
    shadowSize_ = quality.shadowSize;
    meshProg_ =
        quality.pixelLighting ? linkProgram(kMeshVs, kMeshFs, error) : linkProgram(kLiteVs, kLiteFs, error);
    depthProg_ = linkProgram(kDepthVs, kDepthFs, error);
    skyProg_ = linkProgram(kSkyVs, kSkyFs, error);
    particleProg_ = linkProgram(kParticleVs, kParticleFs, error);
    lineProg_ = linkProgram(kLineVs, kLineFs, error);
    chipProg_ = linkProgram(kChipVs, kChipFs, error);
    if (!meshProg_ || !depthProg_ || !skyProg_ || !particleProg_ || !lineProg_ || !chipProg_)
        return false;

    glGenBuffers(1, &slotBuf_);
    glGenTextures(1, &slotTex_);
    glGenVertexArrays(1, &emptyVao_);

    glGenVertexArrays(1, &particleVao_);
    glBindVertexArray(particleVao_);
    const float quad[] = {-0.5f, -0.5f, 0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f};
    glGenBuffers(1, &particleQuad_);
    glBindBuffer(GL_ARRAY_BUFFER, particleQuad_);
    glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenBuffers(1, &particleInst_);
    glBindBuffer(GL_ARRAY_BUFFER, particleInst_);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 8 * sizeof(float), nullptr);
    glVertexAttribDivisor(1, 1);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                          reinterpret_cast<void*>(4 * sizeof(float)));
    glVertexAttribDivisor(2, 1);

    makeTripleArray(lineVao_, lineVbo_, {});
    glGenVertexArrays(1, &chipVao_);
    glBindVertexArray(chipVao_);
    glGenBuffers(1, &chipVbo_);
    glBindBuffer(GL_ARRAY_BUFFER, chipVbo_);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 7 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float),
                          reinterpret_cast<void*>(4 * sizeof(float)));
    glBindVertexArray(0);

    glGenFramebuffers(1, &shadowFbo_);
    glGenTextures(1, &shadowTex_);
    glBindTexture(GL_TEXTURE_2D, shadowTex_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, shadowSize_, shadowSize_, 0, GL_DEPTH_COMPONENT,
                 GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadowTex_, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        shadows = false;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    interiorTex_ = proceduralTexture("interior");
    return true;
}

void Renderer::shutdown() {
    for (auto& b : batches_) {
        glDeleteBuffers(1, &b.vbo);
        glDeleteVertexArrays(1, &b.vao);
    }
    batches_.clear();
    for (GLuint t : textures_)
        glDeleteTextures(1, &t);
    textures_.clear();
    for (GLuint& t : skyFaces_)
        if (t)
            glDeleteTextures(1, &t), t = 0;
    GLuint progs[] = {meshProg_, depthProg_, skyProg_, particleProg_, lineProg_, chipProg_};
    for (GLuint p : progs)
        if (p)
            glDeleteProgram(p);
}

int Renderer::proceduralTexture(const std::string& kind) {
    const int n = 256;
    std::vector<unsigned char> px(static_cast<size_t>(n) * n * 4);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const float fx = static_cast<float>(x) / n * 8, fy = static_cast<float>(y) / n * 8;
            float r = 0.5f, g = 0.5f, b = 0.5f;
            const float nz = fbm(fx, fy, 8, 7);
            if (kind == "grid") {
                const bool line = (x % 64) < 2 || (y % 64) < 2;
                const bool fine = (x % 16) == 0 || (y % 16) == 0;
                const float base = 0.36f + 0.12f * nz;
                r = base * 0.9f;
                g = base * 1.0f;
                b = base * 0.85f;
                if (fine) {
                    r *= 0.85f;
                    g *= 0.85f;
                    b *= 0.85f;
                }
                if (line) {
                    r = 0.85f;
                    g = 0.75f;
                    b = 0.35f;
                }
            } else if (kind.rfind("interior", 0) == 0) { // interior[-material]: the cut faces' grain
                const std::string m = kind.size() > 9 ? kind.substr(9) : "concrete";
                const bool wood = m == "wood";
                const float grain = wood ? fbm(fx * 0.4f, fy * 6, 16, 31) : fbm(fx * 2, fy * 2, 16, 31);
                const float speck = !wood && hashNoise(x, y, 5) > 0.93f ? 0.12f : 0.0f;
                struct Tone {
                    const char* name;
                    float r, g, b, k;
                };
                static const Tone tones[] = {
                    {"concrete", 0.55f, 0.50f, 0.45f, 0.25f}, {"brick", 0.62f, 0.34f, 0.24f, 0.22f},
                    {"stone", 0.52f, 0.52f, 0.50f, 0.28f},    {"wood", 0.58f, 0.40f, 0.22f, 0.35f},
                    {"glass", 0.72f, 0.84f, 0.86f, 0.10f},    {"steel", 0.46f, 0.48f, 0.52f, 0.12f}};
                Tone t = tones[0];
                for (const Tone& c : tones)
                    if (m == c.name)
                        t = c;
                r = t.r + t.k * grain - speck;
                g = t.g + t.k * 0.9f * grain - speck;
                b = t.b + t.k * 0.75f * grain - speck;
            } else if (kind == "metal") {
                const bool panel = (x % 64) < 2 || (y % 128) < 2;
                r = 0.55f + 0.1f * nz;
                g = 0.58f + 0.1f * nz;
                b = 0.62f + 0.1f * nz;
                if (panel) {
                    r *= 0.6f;
                    g *= 0.6f;
                    b *= 0.6f;
                }
            } else { // concrete / facade
                const bool mortar = (y % 32) < 2 || ((x + ((y / 32) % 2) * 32) % 64) < 2;
                const bool window = (x % 64) > 16 && (x % 64) < 48 && (y % 64) > 20 && (y % 64) < 50;
                r = 0.66f + 0.18f * nz;
                g = 0.62f + 0.16f * nz;
                b = 0.56f + 0.14f * nz;
                if (window) {
                    r = 0.16f + 0.1f * nz;
                    g = 0.22f + 0.1f * nz;
                    b = 0.30f + 0.12f * nz;
                } else if (mortar) {
                    r *= 0.8f;
                    g *= 0.8f;
                    b *= 0.8f;
                }
            }
            unsigned char* p = &px[(static_cast<size_t>(y) * n + x) * 4];
            p[0] = static_cast<unsigned char>(std::clamp(r, 0.0f, 1.0f) * 255);
            p[1] = static_cast<unsigned char>(std::clamp(g, 0.0f, 1.0f) * 255);
            p[2] = static_cast<unsigned char>(std::clamp(b, 0.0f, 1.0f) * 255);
            p[3] = 255;
        }
    textures_.push_back(uploadRgba(px.data(), n, n, quality_));
    texturePaths_.push_back("procedural:" + kind);
    return static_cast<int>(textures_.size()) - 1;
}

int Renderer::materialInterior(const std::string& material) {
    const std::string kind = "interior-" + material;
    for (size_t i = 0; i < texturePaths_.size(); ++i)
        if (texturePaths_[i] == "procedural:" + kind)
            return static_cast<int>(i);
    return proceduralTexture(kind);
}

bool Renderer::setInteriorTexture(const std::filesystem::path& path) {
    std::vector<std::string> ignored;
    const size_t before = textures_.size();
    const int id = loadTexture(path, "interior", ignored);
    if (textures_.size() == before && texturePaths_[static_cast<size_t>(id)] != path.string())
        return false;
    if (!ignored.empty())
        return false;
    interiorTex_ = id;
    return true;
}

int Renderer::loadTexture(const std::filesystem::path& path, const std::string& kind,
                          std::vector<std::string>& warnings) {
    for (size_t i = 0; i < texturePaths_.size(); ++i)
        if (texturePaths_[i] == path.string())
            return static_cast<int>(i);
    int w = 0, h = 0, c = 0;
    unsigned char* data = stbi_load(path.string().c_str(), &w, &h, &c, 4);
    if (!data) {
        warnings.push_back(path.string() + ": texture could not be loaded (" +
                           (stbi_failure_reason() ? stbi_failure_reason() : "?") + "); using a procedural '" +
                           kind + "' texture");
        for (size_t i = 0; i < texturePaths_.size(); ++i)
            if (texturePaths_[i] == "procedural:" + kind)
                return static_cast<int>(i);
        return proceduralTexture(kind);
    }
    textures_.push_back(uploadRgba(data, w, h, quality_));
    texturePaths_.push_back(path.string());
    stbi_image_free(data);
    return static_cast<int>(textures_.size()) - 1;
}

void Renderer::setSkybox(const std::array<std::filesystem::path, 6>& faces,
                         std::vector<std::string>& warnings) {
    // world.cfg order: top, bottom, left, right, front, back; one texture each, drawn on a cube with
    // Irrlicht's face mapping (see bakeSkyCube) so the thesis's images meet without seams.
    std::vector<unsigned char*> data(6, nullptr);
    int w[6], h[6];
    bool ok = true;
    for (int i = 0; i < 6; ++i) {
        int c = 0;
        if (!faces[i].empty())
            data[i] = stbi_load(faces[i].string().c_str(), &w[i], &h[i], &c, 4);
        if (!data[i]) {
            warnings.push_back((faces[i].empty() ? std::string("<none>") : faces[i].string()) +
                               ": skybox image could not be loaded; using the procedural sky");
            ok = false;
            break;
        }
        if (w[i] != w[0] || h[i] != w[0]) {
            // Cube faces must be square and equal: resample (nearest) to the first face's size.
            const int n = w[0];
            auto* fixed = static_cast<unsigned char*>(std::malloc(static_cast<size_t>(n) * n * 4));
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const int sx = x * w[i] / n, sy = y * h[i] / n;
                    std::memcpy(fixed + (static_cast<size_t>(y) * n + x) * 4,
                                data[i] + (static_cast<size_t>(sy) * w[i] + sx) * 4, 4);
                }
            stbi_image_free(data[i]);
            data[i] = fixed;
            w[i] = h[i] = n;
        }
    }
    if (ok)
        for (int i = 0; i < 6; ++i) { // one 2D texture per face: llvmpipe samples these faster than an array
            glGenTextures(1, &skyFaces_[i]);
            glBindTexture(GL_TEXTURE_2D, skyFaces_[i]);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w[0], w[0], 0, GL_RGBA, GL_UNSIGNED_BYTE, data[i]);
            const GLint filter = quality_.nearestTexels ? GL_NEAREST : GL_LINEAR;
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        }
    for (auto* d : data)
        if (d)
            stbi_image_free(d);
}

void Renderer::bakeProceduralSky() {
    // A sky dome with per-vertex colours (gradient, sun glow, hazy horizon): almost free per pixel.
    const V3 sun = norm(sunDir) * -1.0f;
    const V3 fog{0.70f, 0.77f, 0.85f};
    const int slices = 48, stacks = 32;
    auto colour = [&](const V3& d) {
        const float t = d.y;
        const V3 zenith{0.22f, 0.42f, 0.75f}, horizon{0.78f, 0.84f, 0.90f};
        V3 c = lerp(horizon, zenith, std::pow(std::max(t, 0.0f), 0.55f));
        if (t < 0)
            c = lerp(horizon, V3{0.45f, 0.45f, 0.47f}, std::min(-t * 4.0f, 1.0f));
        const float sd = std::max(dot(d, sun), 0.0f);
        c += V3{1.0f, 0.85f, 0.6f} * (std::pow(sd, 12.0f) * 0.3f + std::pow(sd, 80.0f) * 0.6f);
        const float h = std::clamp(t * 6.0f, 0.0f, 1.0f);
        return lerp(fog, c, 0.25f + 0.75f * h);
    };
    std::vector<float> v;
    auto dir = [&](int i, int j) {
        const float th = 3.14159265f * static_cast<float>(j) / stacks;
        const float ph = 2 * 3.14159265f * static_cast<float>(i) / slices;
        return V3{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
    };
    auto push = [&](const V3& d) {
        const V3 c = colour(d);
        const float f[6] = {d.x, d.y, d.z, c.x, c.y, c.z};
        v.insert(v.end(), f, f + 6);
    };
    for (int j = 0; j < stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            const V3 a = dir(i, j), b = dir(i + 1, j), c = dir(i + 1, j + 1), d = dir(i, j + 1);
            push(a), push(b), push(c), push(a), push(c), push(d);
        }
    skyVertices_ = static_cast<int>(v.size() / 6);
    makeTripleArray(skyVao_, skyVbo_, v);
}

void Renderer::bakeSkyCube() {
    // The six images on a cube, with the face and UVs of Irrlicht's CSkyBoxSceneNode at every corner: a cube
    // face is planar, so interpolated UVs equal the per-pixel mapping.
    struct Face {
        int axis;   // 0 x, 1 y, 2 z
        float sign; // which side
        int layer;  // world.cfg order: top, bottom, left, right, front, back
    };
    const Face faces[6] = {{1, 1, 0},  {1, -1, 1}, {0, 1, 2},
                           {0, -1, 3}, {2, -1, 4}, {2, 1, 5}}; // layer order
    auto uvOf = [](const Face& f, const float p[3]) -> std::array<float, 2> {
        switch (f.layer) {
        case 0:
            return {(1 - p[2]) * 0.5f, (1 + p[0]) * 0.5f};
        case 1:
            return {(1 - p[2]) * 0.5f, (1 - p[0]) * 0.5f};
        case 2:
            return {(1 - p[2]) * 0.5f, (1 - p[1]) * 0.5f};
        case 3:
            return {(1 + p[2]) * 0.5f, (1 - p[1]) * 0.5f};
        case 4:
            return {(1 - p[0]) * 0.5f, (1 - p[1]) * 0.5f};
        default:
            return {(1 + p[0]) * 0.5f, (1 - p[1]) * 0.5f};
        }
    };
    std::vector<float> v;
    for (const Face& f : faces) {
        const int a = (f.axis + 1) % 3, b = (f.axis + 2) % 3;
        const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int k : {0, 1, 2, 0, 2, 3}) {
            float p[3];
            p[f.axis] = f.sign;
            p[a] = corners[k][0];
            p[b] = corners[k][1];
            const auto uv = uvOf(f, p);
            const float vert[6] = {p[0], p[1], p[2], uv[0], uv[1], 0.0f};
            v.insert(v.end(), vert, vert + 6);
        }
    }
    makeTripleArray(cubeVao_, cubeVbo_, v);
}

int Renderer::batchFor(int texture, bool interior) {
    // cut faces: one batch per interior texture (-1: the default interior texture)
    for (size_t i = 0; i < batches_.size(); ++i)
        if (batches_[i].texture == texture && batches_[i].interior == interior)
            return static_cast<int>(i);
    Batch b;
    b.texture = texture;
    b.interior = interior;
    const int shown = interior && texture < 0 ? interiorTex_ : texture;
    if (shown >= 0 && static_cast<size_t>(shown) < textures_.size()) {
        // the texture's mean colour: its smallest mip level, averaged
        glBindTexture(GL_TEXTURE_2D, textures_[static_cast<size_t>(shown)]);
        int level = 0, w = 0, h = 0;
        for (int l = 0; l < 16; ++l) {
            GLint lw = 0, lh = 0;
            glGetTexLevelParameteriv(GL_TEXTURE_2D, l, GL_TEXTURE_WIDTH, &lw);
            glGetTexLevelParameteriv(GL_TEXTURE_2D, l, GL_TEXTURE_HEIGHT, &lh);
            if (lw <= 0 || lh <= 0)
                break;
            level = l, w = lw, h = lh;
        }
        if (w > 0 && h > 0 && w * h <= 4096) {
            std::vector<unsigned char> px(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
            glGetTexImage(GL_TEXTURE_2D, level, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
            float sum[3] = {0, 0, 0};
            for (size_t i = 0; i < px.size(); i += 4)
                for (int c = 0; c < 3; ++c)
                    sum[c] += static_cast<float>(px[i + static_cast<size_t>(c)]) / 255.0f;
            const float n = static_cast<float>(w * h);
            b.average = {sum[0] / n, sum[1] / n, sum[2] / n};
        }
    }
    glGenVertexArrays(1, &b.vao);
    glGenBuffers(1, &b.vbo);
    glBindVertexArray(b.vao);
    glBindBuffer(GL_ARRAY_BUFFER, b.vbo);
    const GLsizei stride = kFloatsPerVertex * sizeof(float);
    const int sizes[] = {3, 3, 2, 1};
    size_t off = 0;
    for (int a = 0; a < 4; ++a) {
        glEnableVertexAttribArray(static_cast<GLuint>(a));
        glVertexAttribPointer(static_cast<GLuint>(a), sizes[a], GL_FLOAT, GL_FALSE, stride,
                              reinterpret_cast<void*>(off * sizeof(float)));
        off += static_cast<size_t>(sizes[a]);
    }
    glBindVertexArray(0);
    batches_.push_back(std::move(b));
    return static_cast<int>(batches_.size()) - 1;
}

int Renderer::addMesh(const rubble::Mesh& mesh, int texture, float r, float g, float b, int interiorTexture) {
    int id;
    if (!freeIds_.empty()) {
        id = freeIds_.back();
        freeIds_.pop_back();
    } else {
        id = static_cast<int>(meshes_.size());
        meshes_.emplace_back();
    }
    MeshRec& rec = meshes_[id];
    rec.alive = true;
    for (int range = 0; range < 2; ++range) {
        const bool interior = range == 1;
        const int bi = batchFor(interior ? interiorTexture : texture, interior);
        Batch& batch = batches_[bi];
        rec.batch[range] = bi;
        rec.first[range] = static_cast<int>(batch.cpu.size() / kFloatsPerVertex);
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            if ((mesh.material(t) == rubble::kInteriorMaterial) != interior)
                continue;
            const rubble::Vec3 fn = rubble::normalized(mesh.triangleNormal(t));
            for (int c = 0; c < 3; ++c) {
                const rubble::Vec3& p = mesh.positions[mesh.triangles[t][static_cast<size_t>(c)]];
                const rubble::Vec3 n = mesh.hasNormals() ? mesh.normals[3 * t + static_cast<size_t>(c)] : fn;
                const rubble::Vec2 uv =
                    mesh.hasUvs() ? mesh.uvs[3 * t + static_cast<size_t>(c)] : rubble::Vec2{};
                const float v[kFloatsPerVertex] = {
                    static_cast<float>(p.x),  static_cast<float>(p.y),  static_cast<float>(p.z),
                    static_cast<float>(n.x),  static_cast<float>(n.y),  static_cast<float>(n.z),
                    static_cast<float>(uv.x), static_cast<float>(uv.y), static_cast<float>(id)};
                batch.cpu.insert(batch.cpu.end(), v, v + kFloatsPerVertex);
            }
        }
        rec.count[range] = static_cast<int>(batch.cpu.size() / kFloatsPerVertex) - rec.first[range];
    }
    {
        const rubble::Aabb box = mesh.bounds();
        const rubble::Vec3 c = box.center(), h = box.size() * 0.5;
        rec.centre = {static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z)};
        rec.radius = static_cast<float>(std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z));
    }
    { // mean of the outside and the cut faces by triangle count, in the per-vertex path's light on a
      // surface facing the sun half-way, with its tone map and gamma
        const float lit[3] = {0.155f + 0.72f, 0.172f + 0.67f, 0.209f + 0.59f};
        const float tints[2][3] = {{r, g, b}, {0.85f, 0.78f, 0.70f}};
        const float total = static_cast<float>(std::max(1, rec.count[0] + rec.count[1]));
        float out[3] = {0, 0, 0};
        for (int range = 0; range < 2; ++range) {
            const V3 a = batches_[rec.batch[range]].average;
            const float avg[3] = {a.x, a.y, a.z}, share = static_cast<float>(rec.count[range]) / total;
            for (int c = 0; c < 3; ++c) {
                const float l = tints[range][c] * lit[c];
                out[c] += share * avg[c] * std::sqrt(l / (1.0f + 0.15f * l));
            }
        }
        rec.chip = {out[0], out[1], out[2]};
    }
    ++liveMeshes_;
    const size_t need = static_cast<size_t>(id + 1) * kTexelsPerSlot * 4;
    if (slotData_.size() < need)
        slotData_.resize(need, 0.0f);
    float* s = &slotData_[static_cast<size_t>(id) * kTexelsPerSlot * 4];
    s[20] = r;
    s[21] = g;
    s[22] = b;
    return id;
}

void Renderer::removeMesh(int id) {
    if (id < 0 || id >= static_cast<int>(meshes_.size()) || !meshes_[id].alive)
        return;
    MeshRec& rec = meshes_[id];
    rec.alive = false;
    freeIds_.push_back(id);
    --liveMeshes_;
    for (int range = 0; range < 2; ++range) {
        Batch& b = batches_[rec.batch[range]];
        b.dead += rec.count[range];
        if (b.dead > 30000 && b.dead * 2 > static_cast<int>(b.cpu.size() / kFloatsPerVertex))
            compact(b, rec.batch[range]);
    }
}

void Renderer::compact(Batch& b, int batchIndex) {
    std::vector<float> fresh;
    fresh.reserve(b.cpu.size() / 2);
    for (auto& rec : meshes_)
        for (int range = 0; range < 2; ++range) {
            if (!rec.alive || rec.batch[range] != batchIndex)
                continue;
            const int first = static_cast<int>(fresh.size() / kFloatsPerVertex);
            fresh.insert(fresh.end(), b.cpu.begin() + static_cast<long>(rec.first[range]) * kFloatsPerVertex,
                         b.cpu.begin() +
                             static_cast<long>(rec.first[range] + rec.count[range]) * kFloatsPerVertex);
            rec.first[range] = first;
        }
    b.cpu.swap(fresh);
    b.dead = 0;
    b.gpuCapacity = 0;
    b.uploaded = 0;
}

void Renderer::uploadBatch(Batch& b) {
    glBindBuffer(GL_ARRAY_BUFFER, b.vbo);
    const size_t bytes = b.cpu.size() * sizeof(float);
    if (bytes > b.gpuCapacity) {
        b.gpuCapacity = std::max(bytes * 3 / 2, static_cast<size_t>(1 << 16));
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(b.gpuCapacity), nullptr, GL_DYNAMIC_DRAW);
        b.uploaded = 0;
    }
    const size_t from = b.uploaded * sizeof(float);
    glBufferSubData(GL_ARRAY_BUFFER, static_cast<GLintptr>(from), static_cast<GLsizeiptr>(bytes - from),
                    b.cpu.data() + from / sizeof(float));
    b.uploaded = b.cpu.size();
}

void Renderer::beginFrame() {
    for (auto& b : batches_) {
        b.drawn = 0;
        b.firsts.clear();
        b.counts.clear();
        b.shadowFirsts.clear();
        b.shadowCounts.clear();
    }
    queued_.clear();
    chips_.clear();
    dust_.clear();
    sparks_.clear();
    lines_.clear();
    maxSlotUsed_ = 0;
}

void Renderer::drawMesh(int id, const M4& model, float heat, float fade) {
    if (id < 0 || id >= static_cast<int>(meshes_.size()) || !meshes_[id].alive)
        return;
    queued_.push_back(id);
    float* s = &slotData_[static_cast<size_t>(id) * kTexelsPerSlot * 4];
    std::copy(model.m, model.m + 16, s);
    s[16] = heat;
    s[17] = fade;
    maxSlotUsed_ = std::max(maxSlotUsed_, id + 1);
}

void Renderer::addParticle(const Particle& p, bool additive) {
    auto& v = additive ? sparks_ : dust_;
    const float d[8] = {p.pos.x, p.pos.y, p.pos.z, p.size, p.r, p.g, p.b, p.a};
    v.insert(v.end(), d, d + 8);
}

void Renderer::addLine(const V3& a, const V3& b, float r, float g, float bl) {
    const float d[12] = {a.x, a.y, a.z, r, g, bl, b.x, b.y, b.z, r, g, bl};
    lines_.insert(lines_.end(), d, d + 12);
}

void Renderer::mergeRanges(std::vector<GLint>& firsts, std::vector<GLsizei>& counts) {
    // one range per run of adjacent meshes: fewer draws inside the multi-draw
    thread_local std::vector<std::pair<GLint, GLsizei>> ranges;
    ranges.clear();
    for (size_t i = 0; i < firsts.size(); ++i)
        ranges.emplace_back(firsts[i], counts[i]);
    std::sort(ranges.begin(), ranges.end());
    firsts.clear();
    counts.clear();
    for (const auto& [first, count] : ranges) {
        if (!firsts.empty() && firsts.back() + counts.back() == first)
            counts.back() += count;
        else
            firsts.push_back(first), counts.push_back(count);
    }
}

void Renderer::cullAndBatch(const M4& vp, float pixelsPerRadian, bool lod) {
    // Frustum planes of the view-projection (Gribb-Hartmann), tested against each mesh's bounding sphere.
    float planes[6][4];
    for (int i = 0; i < 6; ++i) {
        const int row = i / 2;
        const float sign = i % 2 == 0 ? 1.0f : -1.0f;
        float len2 = 0;
        for (int c = 0; c < 4; ++c) {
            planes[i][c] = vp.m[c * 4 + 3] + sign * vp.m[c * 4 + row];
            if (c < 3)
                len2 += planes[i][c] * planes[i][c];
        }
        const float inv = 1.0f / std::sqrt(std::max(len2, 1e-12f));
        for (float& v : planes[i])
            v *= inv;
    }
    culled_ = 0;
    meshesDrawn_ = 0;
    chipsDrawn_ = 0;
    visible_.clear();
    for (int id : queued_) {
        const MeshRec& rec = meshes_[id];
        const float* s = &slotData_[static_cast<size_t>(id) * kTexelsPerSlot * 4];
        const V3 c{s[0] * rec.centre.x + s[4] * rec.centre.y + s[8] * rec.centre.z + s[12],
                   s[1] * rec.centre.x + s[5] * rec.centre.y + s[9] * rec.centre.z + s[13],
                   s[2] * rec.centre.x + s[6] * rec.centre.y + s[10] * rec.centre.z + s[14]};
        const float scale = std::sqrt(
            std::max({s[0] * s[0] + s[1] * s[1] + s[2] * s[2], s[4] * s[4] + s[5] * s[5] + s[6] * s[6],
                      s[8] * s[8] + s[9] * s[9] + s[10] * s[10]}));
        const float radius = rec.radius * scale;
        bool inside = true;
        for (const auto& p : planes)
            if (p[0] * c.x + p[1] * c.y + p[2] * c.z + p[3] < -radius) {
                inside = false;
                break;
            }
        if (shadows)
            for (int range = 0; range < 2; ++range)
                if (rec.count[range] > 0) {
                    Batch& b = batches_[rec.batch[range]];
                    b.shadowFirsts.push_back(rec.first[range]);
                    b.shadowCounts.push_back(rec.count[range]);
                }
        if (!inside) {
            ++culled_;
            continue;
        }
        const float w = vp.m[3] * c.x + vp.m[7] * c.y + vp.m[11] * c.z + vp.m[15];
        const float pixels = w > radius ? radius * pixelsPerRadian / w : 1e30f;
        visible_.push_back({id, pixels});
    }
    // the largest on screen keep their triangles (at most the budget); the rest are chips
    size_t meshes = visible_.size();
    const float chipPixels = lod ? quality_.chipPixels : 0.0f;
    if (lod && meshes > static_cast<size_t>(quality_.meshBudget)) {
        meshes = static_cast<size_t>(quality_.meshBudget);
        std::nth_element(visible_.begin(), visible_.begin() + static_cast<long>(meshes), visible_.end(),
                         [](const Visible& a, const Visible& b) { return a.pixels > b.pixels; });
    }
    for (size_t i = 0; i < visible_.size(); ++i) {
        const Visible& v = visible_[i];
        const MeshRec& rec = meshes_[v.id];
        if (i < meshes && v.pixels >= chipPixels) {
            ++meshesDrawn_;
            for (int range = 0; range < 2; ++range)
                if (rec.count[range] > 0) {
                    Batch& b = batches_[rec.batch[range]];
                    b.firsts.push_back(rec.first[range]);
                    b.counts.push_back(rec.count[range]);
                    ++b.drawn;
                }
            continue;
        }
        ++chipsDrawn_;
        const float* s = &slotData_[static_cast<size_t>(v.id) * kTexelsPerSlot * 4];
        const V3 c{s[0] * rec.centre.x + s[4] * rec.centre.y + s[8] * rec.centre.z + s[12],
                   s[1] * rec.centre.x + s[5] * rec.centre.y + s[9] * rec.centre.z + s[13],
                   s[2] * rec.centre.x + s[6] * rec.centre.y + s[10] * rec.centre.z + s[14]};
        // a shard covers about the square of 0.9 bounding radii
        const float d[7] = {c.x,        c.y,        c.z,       std::max(1.0f, 0.9f * v.pixels),
                            rec.chip.x, rec.chip.y, rec.chip.z};
        chips_.insert(chips_.end(), d, d + 7);
    }
    for (auto& b : batches_) {
        mergeRanges(b.firsts, b.counts);
        mergeRanges(b.shadowFirsts, b.shadowCounts);
    }
    batchOrder_.resize(batches_.size());
    for (size_t i = 0; i < batches_.size(); ++i)
        batchOrder_[i] = static_cast<int>(i);
    std::stable_sort(batchOrder_.begin(), batchOrder_.end(),
                     [this](int a, int b) { return batches_[a].drawn > batches_[b].drawn; });
    queued_.clear();
}

void Renderer::drawBatches(bool depthOnly, GLuint program) {
    const GLint interiorLoc = depthOnly ? -1 : loc(program, "uInterior");
    for (const int index : batchOrder_) {
        Batch& b = batches_[static_cast<size_t>(index)];
        const auto& firsts = depthOnly ? b.shadowFirsts : b.firsts;
        const auto& counts = depthOnly ? b.shadowCounts : b.counts;
        if (firsts.empty())
            continue;
        if (!depthOnly) {
            glActiveTexture(GL_TEXTURE0);
            glBindTexture(
                GL_TEXTURE_2D,
                textures_[static_cast<size_t>(b.interior && b.texture < 0 ? interiorTex_ : b.texture)]);
            glUniform1i(interiorLoc, b.interior ? 1 : 0);
        }
        glBindVertexArray(b.vao);
        glMultiDrawArrays(GL_TRIANGLES, firsts.data(), counts.data(), static_cast<GLsizei>(firsts.size()));
        ++drawCalls_;
        if (!depthOnly)
            for (GLsizei c : counts)
                triangles_ += c / 3;
    }
}

void Renderer::render(const FrameView& fv) {
    static const char* skipEnv = std::getenv("RUBBLE_DEMO_SKIP");
    const std::string skip = skipEnv ? skipEnv : "";
    drawCalls_ = 0;
    triangles_ = 0;
    for (auto& b : batches_)
        if (b.uploaded < b.cpu.size())
            uploadBatch(b);
    cullAndBatch(fv.proj * fv.view, fv.proj.m[5] * 0.5f * static_cast<float>(fv.height),
                 skip.find("lod") == std::string::npos);

    // Per-object transforms → buffer texture.
    const size_t floats = static_cast<size_t>(std::max(maxSlotUsed_, 1)) * kTexelsPerSlot * 4;
    if (slotData_.size() < floats)
        slotData_.resize(floats, 0.0f);
    glBindBuffer(GL_TEXTURE_BUFFER, slotBuf_);
    if (floats * sizeof(float) > slotCapacity_) {
        slotCapacity_ = floats * sizeof(float) * 2;
        glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(slotCapacity_), nullptr, GL_STREAM_DRAW);
    }
    glBufferSubData(GL_TEXTURE_BUFFER, 0, static_cast<GLsizeiptr>(floats * sizeof(float)), slotData_.data());
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_BUFFER, slotTex_);
    glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, slotBuf_);

    // Shadow map: orthographic from the sun around the focus point.
    const V3 sun = norm(sunDir);
    const float extent = 140.0f;
    const V3 lightEye = fv.focus - sun * 400.0f;
    const M4 lightView = lookAt(lightEye, fv.focus, std::fabs(sun.y) > 0.99f ? V3{0, 0, 1} : V3{0, 1, 0});
    const M4 lightVP = ortho(-extent, extent, -extent, extent, 1.0f, 900.0f) * lightView;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_BLEND);
    if (shadows && skip.find("shadow") == std::string::npos) {
        glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo_);
        glViewport(0, 0, shadowSize_, shadowSize_);
        glClear(GL_DEPTH_BUFFER_BIT);
        glDisable(GL_CULL_FACE);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(2.0f, 4.0f);
        glUseProgram(depthProg_);
        glUniform1i(loc(depthProg_, "uSlots"), 3);
        glUniformMatrix4fv(loc(depthProg_, "uViewProj"), 1, GL_FALSE, lightVP.m);
        drawBatches(true, depthProg_);
        glDisable(GL_POLYGON_OFFSET_FILL);
    }

    glBindFramebuffer(GL_FRAMEBUFFER, fv.fbo);
    glViewport(0, 0, fv.width, fv.height);
    const V3 fog{0.70f, 0.77f, 0.85f};
    glClearColor(fog.x, fog.y, fog.z, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const M4 viewProj = fv.proj * fv.view;

    glUseProgram(meshProg_);
    glUniform1i(loc(meshProg_, "uSlots"), 3);
    glUniform1i(loc(meshProg_, "uTex"), 0);
    glUniform1i(loc(meshProg_, "uShadow"), 2);
    glUniform1i(loc(meshProg_, "uUseShadow"), shadows ? 1 : 0);
    glUniformMatrix4fv(loc(meshProg_, "uViewProj"), 1, GL_FALSE, viewProj.m);
    glUniformMatrix4fv(loc(meshProg_, "uLightVP"), 1, GL_FALSE, lightVP.m);
    glUniform3f(loc(meshProg_, "uSunDir"), sun.x, sun.y, sun.z);
    glUniform3f(loc(meshProg_, "uCamPos"), fv.eye.x, fv.eye.y, fv.eye.z);
    glUniform3f(loc(meshProg_, "uFogColor"), fog.x, fog.y, fog.z);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, shadowTex_);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    if (skip.find("mesh") == std::string::npos)
        drawBatches(false, meshProg_);
    glDisable(GL_CULL_FACE);
    if (!chips_.empty() && skip.find("chips") == std::string::npos) {
        glUseProgram(chipProg_);
        glUniformMatrix4fv(loc(chipProg_, "uViewProj"), 1, GL_FALSE, viewProj.m);
        glUniform3f(loc(chipProg_, "uCamPos"), fv.eye.x, fv.eye.y, fv.eye.z);
        glUniform3f(loc(chipProg_, "uFogColor"), fog.x, fog.y, fog.z);
        glEnable(GL_PROGRAM_POINT_SIZE);
        glBindVertexArray(chipVao_);
        glBindBuffer(GL_ARRAY_BUFFER, chipVbo_);
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(chips_.size() * sizeof(float)), chips_.data(),
                     GL_STREAM_DRAW);
        glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(chips_.size() / 7));
        glDisable(GL_PROGRAM_POINT_SIZE);
        ++drawCalls_;
    }

    // Sky behind everything (drawn last among opaque passes so early depth rejects covered pixels).
    M4 viewNoT = fv.view;
    viewNoT.m[12] = viewNoT.m[13] = viewNoT.m[14] = 0;
    const M4 vp = fv.proj * viewNoT;
    if (!skyVao_)
        bakeProceduralSky();
    const bool cube = skyFaces_[0] != 0;
    if (cube && !cubeVao_)
        bakeSkyCube();
    glUseProgram(skyProg_);
    glUniformMatrix4fv(loc(skyProg_, "uViewProj"), 1, GL_FALSE, vp.m);
    glUniform1i(loc(skyProg_, "uHasCube"), cube ? 1 : 0);
    glUniform1i(loc(skyProg_, "uFaces"), 4);
    glActiveTexture(GL_TEXTURE4);

    glDepthMask(GL_FALSE);
    glBindVertexArray(cube ? cubeVao_ : skyVao_);
    if (skip.find("sky") != std::string::npos) {
    } else if (cube) {
        for (int i = 0; i < 6; ++i) { // faces in layer order, six vertices each
            glBindTexture(GL_TEXTURE_2D, skyFaces_[i]);
            glDrawArrays(GL_TRIANGLES, 6 * i, 6);
        }
        drawCalls_ += 5;
    } else {
        glDrawArrays(GL_TRIANGLES, 0, skyVertices_);
    }
    ++drawCalls_;
    glDepthMask(GL_TRUE);

    // Debug lines.
    if (!lines_.empty()) {
        glUseProgram(lineProg_);
        glUniformMatrix4fv(loc(lineProg_, "uViewProj"), 1, GL_FALSE, viewProj.m);
        glBindVertexArray(lineVao_);
        glBindBuffer(GL_ARRAY_BUFFER, lineVbo_);
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(lines_.size() * sizeof(float)), lines_.data(),
                     GL_STREAM_DRAW);
        glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(lines_.size() / 6));
        ++drawCalls_;
    }

    // Particles: dust (alpha), then sparks (additive); depth test on, no depth writes.
    glUseProgram(particleProg_);
    glUniformMatrix4fv(loc(particleProg_, "uViewProj"), 1, GL_FALSE, viewProj.m);
    const V3 right{fv.view.m[0], fv.view.m[4], fv.view.m[8]};
    const V3 up{fv.view.m[1], fv.view.m[5], fv.view.m[9]};
    glUniform3f(loc(particleProg_, "uRight"), right.x, right.y, right.z);
    glUniform3f(loc(particleProg_, "uUp"), up.x, up.y, up.z);
    // one particle covers at most a fifth (software GL: a tenth) of the screen height
    const float maxShare = quality_.software ? 0.1f : 0.2f;
    glUniform1f(loc(particleProg_, "uMaxSize"), maxShare * 2.0f / std::max(fv.proj.m[5], 1e-3f));
    glBindVertexArray(particleVao_);
    glEnable(GL_BLEND);
    glDepthMask(GL_FALSE);
    for (int pass = 0; pass < 2; ++pass) {
        const auto& v = pass == 0 ? dust_ : sparks_;
        if (v.empty() || skip.find("particles") != std::string::npos)
            continue;
        if (pass == 0)
            glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        else
            glBlendFunc(GL_SRC_ALPHA, GL_ONE);
        glUniform1i(loc(particleProg_, "uAdditive"), pass);
        glBindBuffer(GL_ARRAY_BUFFER, particleInst_);
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(float)), v.data(),
                     GL_STREAM_DRAW);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(v.size() / 8));
        ++drawCalls_;
    }
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glBindVertexArray(0);
    glUseProgram(0);
}

} // namespace demo
