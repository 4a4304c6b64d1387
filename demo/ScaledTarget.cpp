#include "ScaledTarget.hpp"

#include <string>

#include "GlProgram.hpp"

namespace demo {

namespace {

const char* kVs = R"(#version 330 core
uniform vec2 uScale;
out vec2 vUv;
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    vUv = (p * 0.5 + 0.5) * uScale;
    gl_Position = vec4(p, 0.0, 1.0);
})";

const char* kFs = R"(#version 330 core
in vec2 vUv;
uniform sampler2D uColor;
out vec4 oColor;
void main() { oColor = texture(uColor, vUv); })";

} // namespace

ScaledTarget::~ScaledTarget() {
    release();
}

void ScaledTarget::release() {
    if (fbo_) {
        glDeleteFramebuffers(1, &fbo_);
        glDeleteTextures(1, &color_);
        glDeleteRenderbuffers(1, &depth_);
    }
    if (program_)
        glDeleteProgram(program_);
    if (vao_)
        glDeleteVertexArrays(1, &vao_);
    fbo_ = color_ = depth_ = program_ = vao_ = 0;
    w_ = h_ = 0;
}

bool ScaledTarget::reserve(int w, int h) {
    if (fbo_ && w <= w_ && h <= h_)
        return true;
    release();
    std::string error;
    program_ = linkProgram(kVs, kFs, error);
    const bool linked = program_ != 0;
    glGenVertexArrays(1, &vao_);
    glGenFramebuffers(1, &fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glGenTextures(1, &color_);
    glBindTexture(GL_TEXTURE_2D, color_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_, 0);
    glGenRenderbuffers(1, &depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_);
    const bool ok = linked && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    w_ = w;
    h_ = h;
    if (!ok)
        release();
    return ok;
}

void ScaledTarget::blitTo(GLuint dst, int w, int h, int outW, int outH) const {
    // A full-screen triangle sampling the target (bilinear): cheaper than glBlitFramebuffer on llvmpipe.
    glBindFramebuffer(GL_FRAMEBUFFER, dst);
    glViewport(0, 0, outW, outH);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glUseProgram(program_);
    glUniform2f(glGetUniformLocation(program_, "uScale"), static_cast<float>(w) / static_cast<float>(w_),
                static_cast<float>(h) / static_cast<float>(h_));
    glUniform1i(glGetUniformLocation(program_, "uColor"), 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, color_);
    glBindVertexArray(vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
}

} // namespace demo
