// The C API (include/rubble/rubble.h) over the C++ library. Every entry point catches everything: no
// exception crosses the ABI. Handles start with a tag, so that a wrong or destroyed handle of another kind is
// refused instead of used.
#include "rubble/rubble.h"

#include "capi/CApiSupport.hpp"

#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/PartConcavity.hpp"
#include "rubble/core/Log.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/Version.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "rubble/structure/Material.hpp"

static_assert(sizeof(rubble::Vec3) == 3 * sizeof(double), "Vec3 is read as 3 doubles");
static_assert(sizeof(rubble::Vec2f) == 2 * sizeof(float) && sizeof(rubble::Vec3f) == 3 * sizeof(float),
              "attributes are read as floats");
static_assert(sizeof(rubble::Triangle) == 3 * sizeof(std::uint32_t), "Triangle is read as 3 uint32");
static_assert(RUBBLE_ERROR_IO == static_cast<int>(rubble::ErrorCode::IoError) &&
                  RUBBLE_ERROR_CANCELLED == static_cast<int>(rubble::ErrorCode::Cancelled),
              "C status codes 1-7 are rubble::ErrorCode");

struct rubble_fracture {
    static constexpr std::uint32_t kTag = 0x46524143; // "FRAC"
    std::uint32_t tag = kTag;
    rubble::FractureResult result;
    std::vector<std::unique_ptr<rubble_mesh>> meshes;                 // one per piece
    std::vector<std::vector<std::vector<rubble::Vec3>>> convexPoints; // [piece][part] corner points
    std::vector<double> concavity;                                    // of each piece's parts (-1: none)
};

struct rubble_world {
    static constexpr std::uint32_t kTag = 0x574f524c; // "WORL"
    std::uint32_t tag = kTag;
    std::unique_ptr<rubble::DestructionWorld> world;
    std::vector<rubble::FractureOutcome> outcomes; // of the latest collect
};

namespace {

using namespace rubble::capi;
using rubble::capi::copy; // overloaded below for mass properties

void copy(const rubble::MassProperties& mass, rubble_mass_properties& out) {
    out.volume = mass.volume;
    copy(mass.centerOfMass, out.center_of_mass);
    copy(mass.inertia, out.inertia);
    copy(mass.principalMoments, out.principal_moments);
    copy(mass.principalAxes, out.principal_axes);
}

rubble_status newMesh(rubble::Mesh mesh, rubble_mesh** out) {
    auto handle = std::make_unique<rubble_mesh>();
    handle->mesh = std::move(mesh);
    *out = handle.release();
    return ok();
}

/// Checks params and turns them into FractureParams; writes the message of what is wrong.
rubble_status toParams(const char* function, const rubble_fracture_params& in, rubble::FractureParams& out) {
    if (in.pattern != RUBBLE_PATTERN_SINGLE_CELL && in.pattern != RUBBLE_PATTERN_SHATTER &&
        in.pattern != RUBBLE_PATTERN_ADAPTIVE)
        return invalid(function, "unknown pattern");
    if (in.backend != RUBBLE_BACKEND_FAST && in.backend != RUBBLE_BACKEND_COREFINE &&
        in.backend != RUBBLE_BACKEND_NEF)
        return invalid(function, "unknown backend");
    if (rubble::Status s = rubble::checkParam("cells", in.cells); !s)
        return invalid(function, s.message().c_str());
    if (rubble::Status s = rubble::checkParam("max_parts", in.max_convex_parts); !s)
        return invalid(function, ("max_convex_parts: " + s.message()).c_str());
    out.pattern = in.pattern == RUBBLE_PATTERN_SHATTER    ? rubble::CellPattern::Shatter
                  : in.pattern == RUBBLE_PATTERN_ADAPTIVE ? rubble::CellPattern::Adaptive
                                                          : rubble::CellPattern::SingleCell;
    out.cells = in.cells;
    out.backend = in.backend == RUBBLE_BACKEND_COREFINE ? rubble::BooleanKind::Corefine
                  : in.backend == RUBBLE_BACKEND_NEF    ? rubble::BooleanKind::Nef
                                                        : rubble::BooleanKind::Fast;
    rubble::RoughnessChoice choice;
    choice.material = in.material ? in.material : "";
    if (!(in.roughness < 0)) // NaN is set (and refused), not unset
        choice.amplitude = in.roughness;
    if (!(in.hurst <= 0))
        choice.hurst = in.hurst;
    if (!(in.feature_size < 0))
        choice.featureSize = in.feature_size;
    auto roughness = rubble::chooseRoughness(choice);
    if (!roughness)
        return invalid(function, roughness.error().message.c_str());
    out.roughness = *roughness;
    return RUBBLE_OK;
}

/// Checks an impact (point, normal, impulse) and turns it into an Impact; writes the message of what is
/// wrong.
rubble_status toImpact(const char* function, const rubble_impact& in, rubble::Impact& out) {
    out.point = vec(in.point);
    out.normal = vec(in.normal);
    out.impulse = in.impulse;
    for (rubble::Status s : {rubble::checkParam("point", out.point), rubble::checkParam("normal", out.normal),
                             rubble::checkParam("impulse", out.impulse)})
        if (!s)
            return invalid(function, s.message().c_str());
    return RUBBLE_OK;
}

/// Writes up to capacity corner points of a convex part.
rubble_status copyPoints(const char* function, const std::vector<rubble::Vec3>& corners, double* points,
                         std::size_t capacity, std::size_t* count) {
    if (!count)
        return invalid(function, "count is null");
    if (capacity > 0 && !points)
        return invalid(function, "points is null but capacity is not 0");
    *count = corners.size();
    const std::size_t n = std::min(capacity, corners.size());
    for (std::size_t i = 0; i < n; ++i)
        copy(corners[i], points + 3 * i);
    return ok();
}

} // namespace

extern "C" {

uint32_t rubble_api_version(void) {
    return RUBBLE_C_API_VERSION;
}

const char* rubble_version(void) {
    return RUBBLE_VERSION_STRING;
}

const char* rubble_last_error(void) {
    return lastError.c_str();
}

const char* rubble_status_name(rubble_status status) {
    switch (status) {
    case RUBBLE_OK:
        return "ok";
    case RUBBLE_ERROR_IO:
    case RUBBLE_ERROR_PARSE:
    case RUBBLE_ERROR_INVALID_INPUT:
    case RUBBLE_ERROR_UNSUPPORTED:
    case RUBBLE_ERROR_NO_INTERSECTION:
    case RUBBLE_ERROR_GEOMETRY:
    case RUBBLE_ERROR_CANCELLED:
        return rubble::toString(static_cast<rubble::ErrorCode>(status));
    case RUBBLE_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
    case RUBBLE_ERROR_OUT_OF_MEMORY:
        return "out of memory";
    case RUBBLE_ERROR_INTERNAL:
        return "internal error";
    }
    return "unknown status";
}

rubble_status rubble_set_log_callback(rubble_log_callback callback, void* user) {
    return guarded(__func__, [&](const char*) {
        if (!callback) {
            rubble::setLogFunction({});
            return ok();
        }
        rubble::setLogFunction([callback, user](rubble::LogLevel level, std::string_view message) {
            const std::string text(message);
            callback(static_cast<int>(level), text.c_str(), user);
        });
        return ok();
    });
}

rubble_status rubble_mesh_create(const double* positions, size_t vertex_count, const uint32_t* indices,
                                 size_t triangle_count, rubble_mesh** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        if ((vertex_count > 0 && !positions) || (triangle_count > 0 && !indices))
            return invalid(fn, "positions or indices is null");
        rubble::Mesh mesh;
        mesh.positions.resize(vertex_count);
        for (std::size_t i = 0; i < vertex_count; ++i)
            mesh.positions[i] = vec(positions + 3 * i);
        mesh.triangles.resize(triangle_count);
        for (std::size_t t = 0; t < triangle_count; ++t)
            mesh.triangles[t] = {indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]};
        if (rubble::Status s = mesh.validate(); !s)
            return fail(s.error());
        return newMesh(std::move(mesh), out);
    });
}

rubble_status rubble_mesh_create_box(const double lo[3], const double hi[3], int subdivisions,
                                     rubble_mesh** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        if (!lo || !hi)
            return invalid(fn, "lo or hi is null");
        if (subdivisions < 1 || subdivisions > 1000)
            return invalid(fn, "subdivisions must be in 1..1000");
        const rubble::Vec3 a = vec(lo), b = vec(hi);
        if (!(a.x < b.x && a.y < b.y && a.z < b.z))
            return fail(RUBBLE_ERROR_INVALID_INPUT, std::string(fn) + ": lo must be below hi on every axis");
        return newMesh(rubble::makeSubdividedBox(a, b, subdivisions), out);
    });
}

rubble_status rubble_mesh_read(const char* path, rubble_mesh** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        if (!path)
            return invalid(fn, "path is null");
        rubble::Result<rubble::Mesh> mesh = rubble::readMesh(path);
        if (!mesh)
            return fail(mesh.error());
        return newMesh(std::move(mesh).value(), out);
    });
}

rubble_status rubble_mesh_write_obj(const rubble_mesh* mesh, const char* path) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(mesh) || !path)
            return invalid(fn, "mesh or path is null or invalid");
        if (rubble::Status s = rubble::writeObj(path, mesh->mesh); !s)
            return fail(s.error());
        return ok();
    });
}

rubble_status rubble_mesh_clone(const rubble_mesh* mesh, rubble_mesh** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        if (!valid(mesh))
            return invalid(fn, "mesh is null or invalid");
        return newMesh(mesh->mesh, out);
    });
}

rubble_status rubble_mesh_destroy(rubble_mesh* mesh) {
    return guarded(__func__, [&](const char* fn) {
        if (valid(mesh) && mesh->ownedByFracture)
            return invalid(fn, "the mesh belongs to a fracture; destroy the fracture instead");
        return destroy(fn, mesh, "not a mesh handle");
    });
}

rubble_status rubble_mesh_get_data(const rubble_mesh* mesh, rubble_mesh_data* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(mesh) || !out)
            return invalid(fn, "mesh or out is null or invalid");
        const rubble::Mesh& m = mesh->mesh;
        out->positions = m.positions.empty() ? nullptr : &m.positions[0].x;
        out->vertex_count = m.positions.size();
        out->indices = m.triangles.empty() ? nullptr : m.triangles[0].data();
        out->triangle_count = m.triangles.size();
        out->materials = m.materials.empty() ? nullptr : m.materials.data();
        out->uvs = m.uvs.empty() ? nullptr : &m.uvs[0].x;
        out->normals = m.normals.empty() ? nullptr : &m.normals[0].x;
        return ok();
    });
}

rubble_status rubble_mesh_repair(rubble_mesh* mesh) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(mesh))
            return invalid(fn, "mesh is null or invalid");
        if (mesh->ownedByFracture)
            return invalid(fn, "the mesh belongs to a fracture; clone it first");
        rubble::repairMesh(mesh->mesh);
        return ok();
    });
}

rubble_status rubble_mesh_check(const rubble_mesh* mesh, rubble_mesh_report* report) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(mesh) || !report)
            return invalid(fn, "mesh or report is null or invalid");
        const rubble::MeshReport r = rubble::checkMesh(mesh->mesh);
        *report = rubble_mesh_report{};
        report->valid = r.valid();
        report->closed = r.closed;
        report->manifold = r.manifold();
        report->oriented = r.oriented;
        report->outward = r.outward;
        report->vertex_count = r.vertices;
        report->triangle_count = r.triangles;
        report->boundary_edges = r.boundaryEdges;
        report->non_manifold_edges = r.nonManifoldEdges;
        report->degenerate_triangles = r.degenerateTriangles;
        report->self_intersections = r.selfIntersections;
        report->problem_count = r.problems.size();
        report->volume = r.volume;
        copy(r.centerOfMass, report->center_of_mass);
        if (r.valid())
            return ok();
        std::string problems;
        for (const std::string& p : r.problems)
            problems += (problems.empty() ? "" : "; ") + p;
        return fail(RUBBLE_ERROR_INVALID_INPUT, "mesh is not a valid solid: " + problems);
    });
}

rubble_status rubble_mesh_mass_properties(const rubble_mesh* mesh, rubble_mass_properties* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(mesh) || !out)
            return invalid(fn, "mesh or out is null or invalid");
        copy(rubble::computeMassProperties(mesh->mesh), *out);
        return ok();
    });
}

rubble_status rubble_fracture_params_init(rubble_fracture_params* params) {
    return guarded(__func__, [&](const char* fn) {
        if (!params)
            return invalid(fn, "params is null");
        const rubble::FractureParams defaults;
        *params = rubble_fracture_params{};
        params->pattern = RUBBLE_PATTERN_SINGLE_CELL;
        params->cells = defaults.cells;
        params->backend = RUBBLE_BACKEND_FAST;
        params->seed = 1;
        params->convex_parts = 1;
        params->max_convex_parts = rubble::DecompositionParams{}.maxParts;
        params->material = nullptr;
        params->roughness = params->hurst = params->feature_size = -1;
        return ok();
    });
}

rubble_status rubble_fracture_mesh(const rubble_mesh* mesh, const rubble_impact* impact,
                                   const rubble_fracture_params* params, rubble_fracture** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        if (!valid(mesh) || !impact)
            return invalid(fn, "mesh or impact is null or invalid");
        rubble_fracture_params p;
        if (params)
            p = *params;
        else
            (void)rubble_fracture_params_init(&p);
        rubble::FractureParams fp;
        if (rubble_status s = toParams(fn, p, fp); s != RUBBLE_OK)
            return s;
        rubble::Impact hit;
        if (rubble_status s = toImpact(fn, *impact, hit); s != RUBBLE_OK)
            return s;
        rubble::Result<rubble::FractureResult> broken = rubble::fracture(mesh->mesh, hit, fp, p.seed);
        if (!broken)
            return fail(broken.error());
        auto handle = std::make_unique<rubble_fracture>();
        handle->result = std::move(broken).value();
        if (p.convex_parts) {
            rubble::DecompositionParams dp;
            dp.maxParts = p.max_convex_parts;
            rubble::Result<rubble::Decomposition> parent = rubble::decompose(mesh->mesh, dp);
            if (!parent)
                return fail(parent.error());
            const std::vector<std::vector<rubble::ConvexPolytope>> pieceParts =
                rubble::updateDecomposition(parent->parts, handle->result, dp);
            handle->concavity = rubble::pieceConcavity(handle->result, pieceParts);
            for (const std::vector<rubble::ConvexPolytope>& parts : pieceParts) {
                auto& points = handle->convexPoints.emplace_back();
                for (const rubble::ConvexPolytope& part : parts)
                    points.push_back(part.vertices());
            }
        }
        handle->convexPoints.resize(handle->result.pieces.size());
        handle->concavity.resize(handle->result.pieces.size(), -1.0);
        for (rubble::Piece& piece : handle->result.pieces) {
            auto m = std::make_unique<rubble_mesh>();
            m->ownedByFracture = true;
            m->mesh = std::move(piece.mesh);
            handle->meshes.push_back(std::move(m));
        }
        *out = handle.release();
        return ok();
    });
}

rubble_status rubble_fracture_destroy(rubble_fracture* fracture) {
    return guarded(__func__, [&](const char* fn) { return destroy(fn, fracture, "not a fracture handle"); });
}

rubble_status rubble_fracture_get_info(const rubble_fracture* fracture, rubble_fracture_info* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(fracture) || !out)
            return invalid(fn, "fracture or out is null or invalid");
        const rubble::FractureResult& r = fracture->result;
        out->piece_count = r.pieces.size();
        out->input_volume = r.inputVolume;
        out->dropped_volume = r.droppedVolume;
        out->exact_fallback = r.stats.exactFallback;
        out->total_ms = r.stats.timings.totalMs;
        return ok();
    });
}

rubble_status rubble_fracture_get_piece(const rubble_fracture* fracture, size_t index, rubble_piece* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(fracture) || !out)
            return invalid(fn, "fracture or out is null or invalid");
        if (index >= fracture->result.pieces.size())
            return invalid(fn, "piece index out of range");
        const rubble::Piece& piece = fracture->result.pieces[index];
        out->mesh = fracture->meshes[index].get();
        copy(piece.mass, out->mass);
        out->cell = piece.cell;
        out->convex_part_count = fracture->convexPoints[index].size();
        out->concavity = fracture->concavity[index];
        return ok();
    });
}

rubble_status rubble_fracture_get_convex_part(const rubble_fracture* fracture, size_t piece, size_t part,
                                              double* points, size_t capacity, size_t* count) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(fracture))
            return invalid(fn, "fracture is null or invalid");
        if (piece >= fracture->convexPoints.size() || part >= fracture->convexPoints[piece].size())
            return invalid(fn, "piece or part index out of range");
        return copyPoints(fn, fracture->convexPoints[piece][part], points, capacity, count);
    });
}

rubble_status rubble_world_config_init(rubble_world_config* config) {
    return guarded(__func__, [&](const char* fn) {
        if (!config)
            return invalid(fn, "config is null");
        const rubble::DestructionWorld::Config defaults;
        config->workers = defaults.workers;
        config->deterministic = defaults.deterministic;
        config->seed = defaults.seed;
        return ok();
    });
}

rubble_status rubble_world_create(const rubble_world_config* config, rubble_world** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        rubble_world_config c;
        if (config)
            c = *config;
        else
            (void)rubble_world_config_init(&c);
        if (c.workers == 0 || c.workers < -1 || c.workers > 256)
            return invalid(fn, "workers must be -1 (automatic) or 1..256");
        rubble::DestructionWorld::Config wc;
        wc.workers = c.workers;
        wc.deterministic = c.deterministic != 0;
        wc.seed = c.seed;
        auto handle = std::make_unique<rubble_world>();
        handle->world = std::make_unique<rubble::DestructionWorld>(wc);
        *out = handle.release();
        return ok();
    });
}

rubble_status rubble_world_destroy(rubble_world* world) {
    return guarded(__func__, [&](const char* fn) { return destroy(fn, world, "not a world handle"); });
}

rubble_status rubble_object_desc_init(rubble_object_desc* desc) {
    return guarded(__func__, [&](const char* fn) {
        if (!desc)
            return invalid(fn, "desc is null");
        const rubble::ObjectDesc defaults;
        *desc = rubble_object_desc{};
        desc->density = defaults.density;
        desc->impulse_threshold = defaults.impulseThreshold;
        desc->destructible = defaults.destructible;
        return rubble_fracture_params_init(&desc->fracture);
    });
}

rubble_status rubble_world_add_object(rubble_world* world, const rubble_object_desc* desc, uint32_t* id) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world) || !desc || !id)
            return invalid(fn, "world, desc or id is null or invalid");
        if (!valid(desc->mesh))
            return invalid(fn, "desc->mesh is null or invalid");
        if (rubble::Status s = rubble::checkParam("density", desc->density); !s)
            return invalid(fn, s.message().c_str());
        rubble::ObjectDesc od;
        od.mesh = desc->mesh->mesh;
        od.density = desc->density;
        od.impulseThreshold = desc->impulse_threshold;
        od.destructible = desc->destructible != 0;
        if (rubble_status s = toParams(fn, desc->fracture, od.fracture); s != RUBBLE_OK)
            return s;
        rubble::Result<rubble::ObjectId> added = world->world->addObject(std::move(od));
        if (!added)
            return fail(added.error());
        *id = *added;
        return ok();
    });
}

rubble_status rubble_world_remove_object(rubble_world* world, uint32_t id) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world))
            return invalid(fn, "world is null or invalid");
        if (!world->world->object(id))
            return invalid(fn, "no object with this id");
        world->world->removeObject(id);
        return ok();
    });
}

rubble_status rubble_world_submit_impact(rubble_world* world, uint32_t id, const rubble_impact* impact,
                                         int* accepted) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world) || !impact)
            return invalid(fn, "world or impact is null or invalid");
        rubble::Impact hit;
        if (rubble_status s = toImpact(fn, *impact, hit); s != RUBBLE_OK)
            return s;
        const bool taken = world->world->submitImpact(id, hit);
        if (accepted)
            *accepted = taken;
        return ok();
    });
}

rubble_status rubble_world_begin_frame(rubble_world* world) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world))
            return invalid(fn, "world is null or invalid");
        world->world->beginFrame();
        return ok();
    });
}

rubble_status rubble_world_wait_idle(rubble_world* world) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world))
            return invalid(fn, "world is null or invalid");
        world->world->waitIdle();
        return ok();
    });
}

rubble_status rubble_world_collect(rubble_world* world, size_t* outcome_count) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world) || !outcome_count)
            return invalid(fn, "world or outcome_count is null or invalid");
        world->outcomes = world->world->collect();
        for (const rubble::FractureOutcome& o : world->outcomes)
            world->world->commit(o);
        *outcome_count = world->outcomes.size();
        return ok();
    });
}

rubble_status rubble_world_get_outcome(const rubble_world* world, size_t index, rubble_outcome* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world) || !out)
            return invalid(fn, "world or out is null or invalid");
        if (index >= world->outcomes.size())
            return invalid(fn, "outcome index out of range");
        const rubble::FractureOutcome& o = world->outcomes[index];
        out->parent = o.parent;
        out->piece_count = o.pieces.size();
        out->dropped_volume = o.droppedVolume + o.dustVolume();
        out->impulse = o.impulse();
        return ok();
    });
}

rubble_status rubble_world_get_outcome_piece(const rubble_world* world, size_t index, size_t piece,
                                             rubble_outcome_piece* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world) || !out)
            return invalid(fn, "world or out is null or invalid");
        if (index >= world->outcomes.size() || piece >= world->outcomes[index].pieces.size())
            return invalid(fn, "outcome or piece index out of range");
        const rubble::AdoptedPiece& p = world->outcomes[index].pieces[piece];
        out->id = p.id;
        copy(p.frame.rotation, out->rotation);
        copy(p.frame.translation, out->translation);
        out->cell = p.cell;
        return ok();
    });
}

rubble_status rubble_world_object_count(const rubble_world* world, size_t* count) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world) || !count)
            return invalid(fn, "world or count is null or invalid");
        *count = world->world->objects().size();
        return ok();
    });
}

rubble_status rubble_world_get_object(const rubble_world* world, uint32_t id, rubble_object_info* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world) || !out)
            return invalid(fn, "world or out is null or invalid");
        const rubble::ObjectState* s = world->world->object(id);
        if (!s)
            return invalid(fn, "no object with this id");
        out->id = s->id;
        out->version = s->version;
        out->destructible = s->destructible;
        copy(s->mass, out->mass);
        out->density = s->density;
        out->triangle_count = s->mesh.triangleCount();
        out->convex_part_count = s->convexParts.size();
        return ok();
    });
}

rubble_status rubble_world_copy_object_mesh(const rubble_world* world, uint32_t id, rubble_mesh** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        if (!valid(world))
            return invalid(fn, "world is null or invalid");
        const rubble::ObjectState* s = world->world->object(id);
        if (!s)
            return invalid(fn, "no object with this id");
        return newMesh(s->mesh, out);
    });
}

rubble_status rubble_world_get_convex_part(const rubble_world* world, uint32_t id, size_t part,
                                           double* points, size_t capacity, size_t* count) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(world))
            return invalid(fn, "world is null or invalid");
        const rubble::ObjectState* s = world->world->object(id);
        if (!s)
            return invalid(fn, "no object with this id");
        if (part >= s->convexParts.size())
            return invalid(fn, "part index out of range");
        return copyPoints(fn, s->convexParts[part].vertices(), points, capacity, count);
    });
}

} // extern "C"
