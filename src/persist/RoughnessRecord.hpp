#pragma once
// Private to the persist module (and its tests): a Roughness in a snapshot's object record (version 4).

#include "persist/Bytes.hpp"
#include "rubble/fracture/Roughness.hpp"

namespace rubble::persist {

/// Writes r: f64 amplitude, featureSize, hurst, i32 octaves, u8 relative, u64 seed, f64 grainStretch, grain
/// (3 f64), i32 maxTrianglesPerPiece (73 bytes).
inline void writeRoughness(ByteWriter& w, const Roughness& r) {
    for (double x : {r.amplitude, r.featureSize, r.hurst})
        w.f64(x);
    w.i32(r.octaves);
    w.u8(r.relative ? 1 : 0);
    w.u64(r.seed);
    w.f64(r.grainStretch);
    for (double x : {r.grain.x, r.grain.y, r.grain.z})
        w.f64(x);
    w.i32(r.maxTrianglesPerPiece);
}

} // namespace rubble::persist
