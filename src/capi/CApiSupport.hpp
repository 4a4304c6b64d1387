#pragma once
// What the C API's files share: the mesh handle, errors as status codes with the thread's last message, the
// exception guard, handle checks, and conversions of C arrays.

#include <cstdint>
#include <exception>
#include <new>
#include <string>
#include <utility>

#include "rubble/geometry/Mesh.hpp"
#include "rubble/rubble.h"

struct rubble_mesh {
    static constexpr std::uint32_t kTag = 0x4d455348; // "MESH"
    std::uint32_t tag = kTag;
    bool ownedByFracture = false;
    rubble::Mesh mesh;
};

namespace rubble::capi {

inline thread_local std::string lastError;

inline rubble_status fail(rubble_status status, std::string message) {
    lastError = std::move(message);
    return status;
}

inline rubble_status fail(const rubble::Error& error) {
    return fail(static_cast<rubble_status>(error.code), error.message);
}

inline rubble_status invalid(const char* function, const char* what) {
    return fail(RUBBLE_ERROR_INVALID_ARGUMENT, std::string(function) + ": " + what);
}

inline rubble_status ok() {
    lastError.clear();
    return RUBBLE_OK;
}

/// Runs body(function), turning exceptions into status codes.
template <class Body>
rubble_status guarded(const char* function, Body&& body) noexcept {
    try {
        return body(function);
    } catch (const std::bad_alloc&) {
        return fail(RUBBLE_ERROR_OUT_OF_MEMORY, std::string(function) + ": out of memory");
    } catch (const std::exception& e) {
        return fail(RUBBLE_ERROR_INTERNAL, std::string(function) + ": " + e.what());
    } catch (...) {
        return fail(RUBBLE_ERROR_INTERNAL, std::string(function) + ": unknown exception");
    }
}

/// A live handle of this kind (its tag).
template <class Handle>
bool valid(const Handle* h) {
    return h && h->tag == Handle::kTag;
}

/// Deletes a handle of the right kind (null is fine), clearing its tag first.
template <class Handle>
rubble_status destroy(const char* function, Handle* handle, const char* what) {
    if (!handle)
        return ok();
    if (!valid(handle))
        return invalid(function, what);
    handle->tag = 0;
    delete handle;
    return ok();
}

inline rubble::Vec3 vec(const double v[3]) {
    return {v[0], v[1], v[2]};
}

inline void copy(const rubble::Vec3& v, double out[3]) {
    out[0] = v.x;
    out[1] = v.y;
    out[2] = v.z;
}

inline void copy(const rubble::Mat3& m, double out[9]) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            out[3 * r + c] = m.m[r][c];
}

} // namespace rubble::capi
