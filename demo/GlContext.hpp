#pragma once
/// \file GlContext.hpp
/// An OpenGL 3.3 core context: a GLFW window (X11, or Xvfb), or with no display an EGL surfaceless context
/// (EGL_PLATFORM_SURFACELESS_MESA) that renders into an offscreen framebuffer object.

#include <memory>
#include <string>

#include <epoxy/gl.h>

struct GLFWwindow;

namespace demo {

/// Owns the GL context and the default render target.
class GlContext {
public:
    /// Creates a context. headless=true uses EGL surfaceless + FBO (needs no X server).
    static std::unique_ptr<GlContext> create(int width, int height, bool headless, std::string& error);
    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    /// True when rendering offscreen (EGL).
    bool headless() const { return window_ == nullptr; }
    /// The GLFW window (null when headless).
    GLFWwindow* window() const { return window_; }
    /// Framebuffer to render into (0 = window back buffer).
    GLuint framebuffer() const { return fbo_; }
    /// Render target width in pixels.
    int width() const;
    /// Render target height in pixels.
    int height() const;
    /// Presents the frame (swap buffers; no-op when headless).
    void present();
    /// Reads the current render target as tightly packed RGB rows, top row first.
    void readPixels(std::string& rgb, int& w, int& h) const;
    /// GL_RENDERER string.
    std::string renderer() const;

private:
    GlContext() = default;
    GLFWwindow* window_ = nullptr;
    void* eglDisplay_ = nullptr;
    void* eglContext_ = nullptr;
    GLuint fbo_ = 0;
    GLuint color_ = 0;
    GLuint depth_ = 0;
    int w_ = 0;
    int h_ = 0;
};

} // namespace demo
