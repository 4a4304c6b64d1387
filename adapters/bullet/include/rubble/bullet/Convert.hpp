#pragma once
/// \file Convert.hpp
/// Conversions between Rubble's double-precision types and Bullet's (float) math types.

#include <LinearMath/btTransform.h>
#include <LinearMath/btVector3.h>

#include "rubble/core/Vec3.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble::bullet {

/// Rubble vector → Bullet vector.
inline btVector3 toBt(const Vec3& v) {
    return {static_cast<btScalar>(v.x), static_cast<btScalar>(v.y), static_cast<btScalar>(v.z)};
}
/// Bullet vector → Rubble vector.
inline Vec3 fromBt(const btVector3& v) {
    return {v.x(), v.y(), v.z()};
}
/// Rubble matrix → Bullet matrix.
inline btMatrix3x3 toBt(const Mat3& m) {
    return {
        static_cast<btScalar>(m.m[0][0]), static_cast<btScalar>(m.m[0][1]), static_cast<btScalar>(m.m[0][2]),
        static_cast<btScalar>(m.m[1][0]), static_cast<btScalar>(m.m[1][1]), static_cast<btScalar>(m.m[1][2]),
        static_cast<btScalar>(m.m[2][0]), static_cast<btScalar>(m.m[2][1]), static_cast<btScalar>(m.m[2][2])};
}
/// Bullet matrix → Rubble matrix.
inline Mat3 fromBt(const btMatrix3x3& b) {
    Mat3 m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            m.m[i][j] = b[i][j];
    return m;
}
/// Rubble frame → Bullet transform.
inline btTransform toBt(const Frame& f) {
    return btTransform(toBt(f.rotation), toBt(f.translation));
}
/// Bullet transform → Rubble frame.
inline Frame fromBt(const btTransform& t) {
    return Frame{fromBt(t.getBasis()), fromBt(t.getOrigin())};
}

} // namespace rubble::bullet
