#pragma once
/// \file ScaledTarget.hpp
/// An offscreen colour + depth target the scene is drawn into at a reduced size, then stretched (bilinear)
/// onto the output framebuffer.

#include <epoxy/gl.h>

namespace demo {

/// The internal render target of dynamic resolution scaling. Needs the GL context current.
class ScaledTarget {
public:
    ~ScaledTarget();
    /// Makes sure the target holds at least w x h pixels (reallocated only when the output grows).
    bool reserve(int w, int h);
    /// The framebuffer to draw the scene into (viewport: the internal size).
    GLuint framebuffer() const { return fbo_; }
    /// Stretches the w x h corner onto the whole of dst (outW x outH) with a full-screen triangle.
    void blitTo(GLuint dst, int w, int h, int outW, int outH) const;
    /// Frees the GL objects.
    void release();

private:
    GLuint fbo_ = 0, color_ = 0, depth_ = 0, program_ = 0, vao_ = 0;
    int w_ = 0, h_ = 0;
};

} // namespace demo
