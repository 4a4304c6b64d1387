#include "GlContext.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLFW/glfw3.h>

#include <vector>

namespace demo {

namespace {

bool createFbo(int w, int h, GLuint& fbo, GLuint& color, GLuint& depth) {
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, &color);
    glBindRenderbuffer(GL_RENDERBUFFER, color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth);
    return glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
}

} // namespace

std::unique_ptr<GlContext> GlContext::create(int width, int height, bool headless, std::string& error) {
    std::unique_ptr<GlContext> ctx(new GlContext());
    ctx->w_ = width;
    ctx->h_ = height;
    if (!headless) {
        if (!glfwInit()) {
            error = "glfwInit failed (no X display? run without DISPLAY for the EGL path, or under xvfb-run)";
            return nullptr;
        }
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
        glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
        glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
        ctx->window_ = glfwCreateWindow(width, height, "Rubble — destructible worlds", nullptr, nullptr);
        if (!ctx->window_) {
            error = "glfwCreateWindow failed (OpenGL 3.3 core not available?)";
            glfwTerminate();
            return nullptr;
        }
        glfwMakeContextCurrent(ctx->window_);
        glfwSwapInterval(0);
        return ctx;
    }

    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!getPlatformDisplay) {
        error = "EGL: eglGetPlatformDisplayEXT missing";
        return nullptr;
    }
    EGLDisplay dpy = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor)) {
        error = "EGL: surfaceless display could not be initialised (Mesa EGL needed)";
        return nullptr;
    }
    eglBindAPI(EGL_OPENGL_API);
    const EGLint cfgAttr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint n = 0;
    if (!eglChooseConfig(dpy, cfgAttr, &config, 1, &n) || n == 0)
        config = nullptr; // EGL_KHR_no_config_context
    const EGLint ctxAttr[] = {EGL_CONTEXT_MAJOR_VERSION,
                              3,
                              EGL_CONTEXT_MINOR_VERSION,
                              3,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_NONE};
    EGLContext eglCtx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, ctxAttr);
    if (eglCtx == EGL_NO_CONTEXT) {
        error = "EGL: could not create an OpenGL 3.3 core context";
        eglTerminate(dpy);
        return nullptr;
    }
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, eglCtx)) {
        error = "EGL: eglMakeCurrent without surface failed";
        eglDestroyContext(dpy, eglCtx);
        eglTerminate(dpy);
        return nullptr;
    }
    ctx->eglDisplay_ = dpy;
    ctx->eglContext_ = eglCtx;
    if (!createFbo(width, height, ctx->fbo_, ctx->color_, ctx->depth_)) {
        error = "EGL: offscreen framebuffer incomplete";
        return nullptr;
    }
    return ctx;
}

GlContext::~GlContext() {
    if (window_) {
        glfwDestroyWindow(window_);
        glfwTerminate();
    }
    if (eglDisplay_) {
        if (fbo_) {
            glDeleteFramebuffers(1, &fbo_);
            glDeleteRenderbuffers(1, &color_);
            glDeleteRenderbuffers(1, &depth_);
        }
        eglMakeCurrent(eglDisplay_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(eglDisplay_, eglContext_);
        eglTerminate(eglDisplay_);
    }
}

int GlContext::width() const {
    if (window_) {
        int w = 0, h = 0;
        glfwGetFramebufferSize(window_, &w, &h);
        return w;
    }
    return w_;
}

int GlContext::height() const {
    if (window_) {
        int w = 0, h = 0;
        glfwGetFramebufferSize(window_, &w, &h);
        return h;
    }
    return h_;
}

void GlContext::present() {
    if (window_)
        glfwSwapBuffers(window_);
    else
        glFinish(); // offscreen: finish the frame so frame times are honest
}

void GlContext::readPixels(std::string& rgb, int& w, int& h) const {
    w = width();
    h = height();
    std::vector<unsigned char> raw(static_cast<size_t>(w) * h * 3);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    if (!fbo_)
        glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, raw.data());
    rgb.resize(raw.size());
    const size_t row = static_cast<size_t>(w) * 3;
    for (int y = 0; y < h; ++y)
        std::copy(raw.begin() + static_cast<long>((h - 1 - y) * row),
                  raw.begin() + static_cast<long>((h - y) * row), rgb.begin() + static_cast<long>(y * row));
}

std::string GlContext::renderer() const {
    const auto* s = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    return s ? s : "?";
}

} // namespace demo
