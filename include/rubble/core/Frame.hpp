#pragma once
/// \file Frame.hpp
/// A rigid frame (rotation + translation) and its composition.

#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// A rigid frame: p_parent = rotation · p_local + translation.
struct RUBBLE_API Frame {
    Mat3 rotation = Mat3::identity(); ///< orientation
    Vec3 translation;                 ///< position

    /// Maps a point from local to parent coordinates.
    Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
    /// Maps a point from parent to local coordinates.
    Vec3 applyInverse(const Vec3& p) const { return rotation.transposed() * (p - translation); }
    /// The frame that maps parent to local coordinates.
    Frame inverse() const {
        const Mat3 rt = rotation.transposed();
        return Frame{rt, rt * (-1.0 * translation)};
    }
    /// This frame after `local`: p ↦ this(local(p)).
    Frame operator*(const Frame& local) const {
        return Frame{rotation * local.rotation, rotation * local.translation + translation};
    }
};

} // namespace rubble
