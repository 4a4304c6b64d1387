/// \file rubble.h
/// Rubble's C API: the stable ABI that bindings (C#, Rust, Zig, Lua) and engine plug-ins build on.
/// Opaque handles with explicit create/destroy; every function returns a rubble_status, and
/// rubble_last_error() says what went wrong (per thread). No exception crosses this ABI; a null or invalid
/// argument gives RUBBLE_ERROR_INVALID_ARGUMENT, never a crash. Link with librubble (C11 or later).
#ifndef RUBBLE_RUBBLE_H
#define RUBBLE_RUBBLE_H

#include <stddef.h>
#include <stdint.h>

#define RUBBLE_C_API __attribute__((visibility("default")))

/// Declares a C enum; in C++ its underlying type is int, so that any int a caller passes is a valid value
/// (the library then refuses it as an invalid argument instead of reading an out-of-range enum).
#ifdef __cplusplus
#define RUBBLE_C_ENUM(name) enum name : int
#else
#define RUBBLE_C_ENUM(name) enum name
#endif

#ifdef __cplusplus
extern "C" {
#endif

/// Version of this C API; bumped when a struct or a function signature changes.
#define RUBBLE_C_API_VERSION 4

/// What a call returned: RUBBLE_OK or why it failed (1-7 are the library's rubble::ErrorCode values).
typedef RUBBLE_C_ENUM(rubble_status){
    RUBBLE_OK = 0,                      ///< success
    RUBBLE_ERROR_IO = 1,                ///< a file could not be opened, read or written
    RUBBLE_ERROR_PARSE = 2,             ///< a file was read but its content is malformed
    RUBBLE_ERROR_INVALID_INPUT = 3,     ///< a mesh or value violates a precondition (e.g. an open mesh)
    RUBBLE_ERROR_UNSUPPORTED = 4,       ///< a format or feature that is not available
    RUBBLE_ERROR_NO_INTERSECTION = 5,   ///< nothing to act on (e.g. an impact whose cells miss the mesh)
    RUBBLE_ERROR_GEOMETRY = 6,          ///< a geometric kernel failed; the input is unchanged
    RUBBLE_ERROR_CANCELLED = 7,         ///< the operation was cancelled or superseded
    RUBBLE_ERROR_INVALID_ARGUMENT = 64, ///< a null or wrong handle or pointer, an index out of range
    RUBBLE_ERROR_OUT_OF_MEMORY = 65,    ///< an allocation failed
    RUBBLE_ERROR_INTERNAL = 66,         ///< an unexpected failure inside the library (a bug)
} rubble_status;

/// The version of the C API the library implements (RUBBLE_C_API_VERSION it was built with).
RUBBLE_C_API uint32_t rubble_api_version(void);
/// The library's version, "MAJOR.MINOR.PATCH" (RUBBLE_VERSION_STRING of rubble/core/Version.hpp); static.
RUBBLE_C_API const char* rubble_version(void);
/// The message of the last failed call on this thread ("" after a successful one); valid until the next call.
RUBBLE_C_API const char* rubble_last_error(void);
/// A static, lower-case name of a status ("ok", "invalid input", ...).
RUBBLE_C_API const char* rubble_status_name(rubble_status status);

/// Receives the library's log messages (level 0 info, 1 warning, 2 error); may run on worker threads.
typedef void (*rubble_log_callback)(int level, const char* message, void* user);
/// Routes the library's log messages to callback (NULL restores the default: lines on stderr).
RUBBLE_C_API rubble_status rubble_set_log_callback(rubble_log_callback callback, void* user);

/// A triangle mesh (positions, triangles and optional per-corner normals and UVs, per-triangle materials).
typedef struct rubble_mesh rubble_mesh;
/// The pieces of one fracture, with their mass properties and convex collision parts.
typedef struct rubble_fracture rubble_fracture;
/// A destruction world: objects, impacts, fracture jobs on worker threads, outcomes to adopt.
typedef struct rubble_world rubble_world;

/// Read-only view of a mesh's arrays; valid until the mesh is destroyed or changed.
typedef struct rubble_mesh_data {
    const double* positions;   ///< 3 per vertex (x, y, z)
    size_t vertex_count;       ///< number of vertices
    const uint32_t* indices;   ///< 3 per triangle, counter-clockwise seen from outside
    size_t triangle_count;     ///< number of triangles
    const uint32_t* materials; ///< 1 per triangle, or NULL; cut faces carry RUBBLE_INTERIOR_MATERIAL
    const float* uvs;          ///< 2 per triangle corner (6 per triangle), or NULL (float since version 3)
    const float* normals;      ///< 3 per triangle corner (9 per triangle), or NULL (float since version 3)
} rubble_mesh_data;

/// Material id of faces created by a cut (the inside of an object).
#define RUBBLE_INTERIOR_MATERIAL 0xFFFFFFFEu

/// Creates a mesh from vertex positions (3 doubles each) and triangles (3 indices each).
RUBBLE_C_API rubble_status rubble_mesh_create(const double* positions, size_t vertex_count,
                                              const uint32_t* indices, size_t triangle_count,
                                              rubble_mesh** out);
/// Creates a box from lo to hi whose faces are split into an n x n grid (12 n^2 triangles, n >= 1).
RUBBLE_C_API rubble_status rubble_mesh_create_box(const double lo[3], const double hi[3], int subdivisions,
                                                  rubble_mesh** out);
/// Reads a mesh file (.obj, .off, .stl, .ply, .3ds, .gltf, .glb); errors name the file and line.
RUBBLE_C_API rubble_status rubble_mesh_read(const char* path, rubble_mesh** out);
/// Writes a mesh as OBJ (with an MTL file next to it when it has materials).
RUBBLE_C_API rubble_status rubble_mesh_write_obj(const rubble_mesh* mesh, const char* path);
/// A copy of a mesh (e.g. to keep a piece beyond its fracture).
RUBBLE_C_API rubble_status rubble_mesh_clone(const rubble_mesh* mesh, rubble_mesh** out);
/// Destroys a mesh made by a create, read or clone call (NULL is accepted and ignored). A mesh owned by a
/// fracture gives RUBBLE_ERROR_INVALID_ARGUMENT and stays.
RUBBLE_C_API rubble_status rubble_mesh_destroy(rubble_mesh* mesh);
/// The mesh's arrays.
RUBBLE_C_API rubble_status rubble_mesh_get_data(const rubble_mesh* mesh, rubble_mesh_data* out);
/// Repairs common defects in place (duplicate vertices, degenerate triangles, orientation, holes whose
/// boundary is a simple, nearly planar loop); rubble_mesh_check says whether the result is valid.
RUBBLE_C_API rubble_status rubble_mesh_repair(rubble_mesh* mesh);

/// Mass properties for density 1 (multiply volume and inertia by the density).
typedef struct rubble_mass_properties {
    double volume;               ///< volume
    double center_of_mass[3];    ///< centroid of the solid
    double inertia[9];           ///< inertia tensor about the centre of mass, row-major
    double principal_moments[3]; ///< eigenvalues of inertia, ascending
    double principal_axes[9];    ///< row-major; column i is the unit axis of principal_moments[i]
} rubble_mass_properties;

/// What rubble_mesh_check found.
typedef struct rubble_mesh_report {
    int valid;                   ///< 1 when the mesh is a valid closed solid (fracture accepts it)
    int closed;                  ///< every edge has exactly two triangles
    int manifold;                ///< edges and vertices are manifold
    int oriented;                ///< triangles are consistently oriented
    int outward;                 ///< the signed volume is positive
    size_t vertex_count;         ///< vertices
    size_t triangle_count;       ///< triangles
    size_t boundary_edges;       ///< edges with one triangle (holes)
    size_t non_manifold_edges;   ///< edges with three or more triangles
    size_t degenerate_triangles; ///< triangles of zero area
    size_t self_intersections;   ///< intersecting pairs of triangles
    size_t problem_count;        ///< problems found (listed in rubble_last_error() when not valid)
    double volume;               ///< signed volume
    double center_of_mass[3];    ///< centre of mass
} rubble_mesh_report;

/// Checks whether a mesh is a valid solid. Fills report either way; returns RUBBLE_ERROR_INVALID_INPUT when
/// it is not valid, with the problems in rubble_last_error().
RUBBLE_C_API rubble_status rubble_mesh_check(const rubble_mesh* mesh, rubble_mesh_report* report);
/// Exact mass properties of a closed mesh (density 1).
RUBBLE_C_API rubble_status rubble_mesh_mass_properties(const rubble_mesh* mesh, rubble_mass_properties* out);

/// Which cells an impact cuts.
typedef RUBBLE_C_ENUM(rubble_pattern){
    RUBBLE_PATTERN_SINGLE_CELL = 0, ///< one Voronoi cell at the impact (the thesis's method)
    RUBBLE_PATTERN_SHATTER = 1,     ///< `cells` Voronoi cells around the impact, denser near it
    RUBBLE_PATTERN_ADAPTIVE = 2,    ///< per impact: a weak hit chips one cell, one of 400 N s or more
                                    ///< shatters into `cells`; the cut grows with the mesh's size
} rubble_pattern;

/// Which boolean implementation cuts.
typedef RUBBLE_C_ENUM(rubble_backend){
    RUBBLE_BACKEND_FAST = 0,     ///< the convex-cell clipper with exact fallback (default)
    RUBBLE_BACKEND_COREFINE = 1, ///< CGAL corefinement (exact)
    RUBBLE_BACKEND_NEF = 2,      ///< CGAL Nef polyhedra (the thesis's method; slow)
} rubble_backend;

/// An impact in the mesh's coordinates. Calls that take one refuse (RUBBLE_ERROR_INVALID_ARGUMENT, with a
/// message naming the field and its range) a non-finite point, a zero or non-finite normal and an impulse
/// outside [0, 1e12].
typedef struct rubble_impact {
    double point[3];  ///< where it was hit (finite)
    double normal[3]; ///< surface normal there (out of the object; finite, not all 0)
    double impulse;   ///< N s, in [0, 1e12]; bigger impulses cut bigger cells
} rubble_impact;

/// How a mesh breaks; rubble_fracture_params_init sets the defaults.
typedef struct rubble_fracture_params {
    rubble_pattern pattern; ///< single cell, shatter or adaptive
    int cells;              ///< cells of a shatter pattern, 1..1000 (others are refused, not clamped)
    rubble_backend backend; ///< boolean implementation
    uint64_t seed;          ///< same seed, same pieces
    int convex_parts;       ///< 1: compute each piece's convex collision parts (decomposes the input first)
    int max_convex_parts;   ///< at most this many parts per piece (>= 1)
    const char* material; ///< NULL (flat cuts) or a material whose rough cut faces apply (docs/roughness.md)
    double roughness;     ///< amplitude of rough cut faces, a fraction of the cell size; 0 flat; < 0 unset
    double hurst;         ///< Hurst exponent of rough cut faces, in (0, 1]; <= 0 unset
    double feature_size;  ///< longest wavelength of rough cut faces, a fraction of the cell size; < 0 unset
} rubble_fracture_params;

/// The defaults: single cell, 6 shatter cells, Fast backend, seed 1, convex parts on, at most 24 parts, flat
/// cuts (material NULL, roughness, hurst and feature_size unset: -1).
RUBBLE_C_API rubble_status rubble_fracture_params_init(rubble_fracture_params* params);
/// Breaks a closed mesh at an impact. NULL params means the defaults.
RUBBLE_C_API rubble_status rubble_fracture_mesh(const rubble_mesh* mesh, const rubble_impact* impact,
                                                const rubble_fracture_params* params, rubble_fracture** out);
/// Destroys a fracture and the piece meshes it owns (NULL is accepted and ignored).
RUBBLE_C_API rubble_status rubble_fracture_destroy(rubble_fracture* fracture);

/// Totals of a fracture.
typedef struct rubble_fracture_info {
    size_t piece_count;    ///< pieces: remainder islands first, then debris by cell
    double input_volume;   ///< volume of the input mesh
    double dropped_volume; ///< volume of slivers dropped as too small
    int exact_fallback;    ///< 1 when the Fast backend fell back to corefinement
    double total_ms;       ///< wall-clock time of the fracture (without convex parts)
} rubble_fracture_info;

/// One piece of a fracture.
typedef struct rubble_piece {
    const rubble_mesh* mesh;     ///< closed mesh in the input's coordinates; owned by the fracture
    rubble_mass_properties mass; ///< its mass properties (density 1)
    int32_t cell;                ///< -1: part of the damaged remainder; i >= 0: debris of cell i
    size_t convex_part_count;    ///< convex collision parts (0 when they were not computed)
    double concavity;            ///< how far the parts stray from the piece's surface, as a fraction of its
                                 ///< bounding-box diagonal (one-sided Hausdorff); -1 without parts
} rubble_piece;

/// Totals of a fracture.
RUBBLE_C_API rubble_status rubble_fracture_get_info(const rubble_fracture* fracture,
                                                    rubble_fracture_info* out);
/// Piece `index` (< piece_count).
RUBBLE_C_API rubble_status rubble_fracture_get_piece(const rubble_fracture* fracture, size_t index,
                                                     rubble_piece* out);
/// The corner points of convex part `part` of a piece: writes up to `capacity` points (3 doubles each) to
/// points (which may be NULL when capacity is 0) and the number of points to *count.
RUBBLE_C_API rubble_status rubble_fracture_get_convex_part(const rubble_fracture* fracture, size_t piece,
                                                           size_t part, double* points, size_t capacity,
                                                           size_t* count);

/// Settings of a world; rubble_world_config_init sets the defaults.
typedef struct rubble_world_config {
    int workers;       ///< fracture worker threads (-1: hardware threads - 1, at least 1)
    int deterministic; ///< 1: adopt every result a fixed number of frames after its impact (replays)
    uint64_t seed;     ///< world seed; every job's seed derives from it
} rubble_world_config;

/// The defaults: automatic workers, not deterministic, seed 1.
RUBBLE_C_API rubble_status rubble_world_config_init(rubble_world_config* config);
/// Creates a world (NULL config means the defaults).
RUBBLE_C_API rubble_status rubble_world_create(const rubble_world_config* config, rubble_world** out);
/// Destroys a world; waits for its jobs (NULL is accepted and ignored).
RUBBLE_C_API rubble_status rubble_world_destroy(rubble_world* world);

/// What an object is made of; rubble_object_desc_init sets the defaults.
typedef struct rubble_object_desc {
    const rubble_mesh* mesh;         ///< closed mesh in the object's coordinates (copied)
    double density;                  ///< mass = density x volume; in (0, 1e9]
    double impulse_threshold;        ///< impacts below this impulse are ignored
    int destructible;                ///< 0: never breaks
    rubble_fracture_params fracture; ///< how it breaks (seed and convex_parts are ignored: the world decides)
} rubble_object_desc;

/// The defaults: no mesh, density 1, threshold 0, destructible, default fracture parameters.
RUBBLE_C_API rubble_status rubble_object_desc_init(rubble_object_desc* desc);
/// Adds an object (an invalid mesh is repaired, or the object becomes indestructible with a log warning);
/// decomposes it into convex parts. Writes its id.
RUBBLE_C_API rubble_status rubble_world_add_object(rubble_world* world, const rubble_object_desc* desc,
                                                   uint32_t* id);
/// Removes an object; RUBBLE_ERROR_INVALID_ARGUMENT when there is none with this id.
RUBBLE_C_API rubble_status rubble_world_remove_object(rubble_world* world, uint32_t id);
/// Submits an impact in the object's coordinates; *accepted (may be NULL) is 0 when it was ignored (unknown
/// or indestructible object, impulse below its threshold).
RUBBLE_C_API rubble_status rubble_world_submit_impact(rubble_world* world, uint32_t id,
                                                      const rubble_impact* impact, int* accepted);
/// Starts a frame; call once per frame before rubble_world_collect.
RUBBLE_C_API rubble_status rubble_world_begin_frame(rubble_world* world);
/// Blocks until no fracture job is running or queued (tools, tests, loading screens).
RUBBLE_C_API rubble_status rubble_world_wait_idle(rubble_world* world);
/// Adopts the results ready this frame: each parent object is replaced by its pieces (the splits are
/// collected and committed at once). Writes the number of outcomes, which stay readable until the next
/// collect.
RUBBLE_C_API rubble_status rubble_world_collect(rubble_world* world, size_t* outcome_count);

/// One result of the latest collect.
typedef struct rubble_outcome {
    uint32_t parent;       ///< the object that broke (no longer in the world)
    size_t piece_count;    ///< the new objects
    double dropped_volume; ///< volume of slivers and dust dropped
    double impulse;        ///< summed impulse of the impacts that broke it (N*s; since version 4)
} rubble_outcome;

/// A new object of an outcome.
typedef struct rubble_outcome_piece {
    uint32_t id;           ///< its object id
    double rotation[9];    ///< row-major; piece frame -> parent frame: p_parent = R p_piece + t
    double translation[3]; ///< t (the piece's centre of mass in the parent's coordinates; R = 1 and t = 0
                           ///< for a remainder above 20,000 triangles cut in place: its mesh keeps the
                           ///< parent's frame, and its centre of mass is in its object info)
    int32_t cell;          ///< -1: part of the remainder; i >= 0: debris of cell i
} rubble_outcome_piece;

/// Outcome `index` of the latest collect.
RUBBLE_C_API rubble_status rubble_world_get_outcome(const rubble_world* world, size_t index,
                                                    rubble_outcome* out);
/// Piece `piece` of outcome `index`.
RUBBLE_C_API rubble_status rubble_world_get_outcome_piece(const rubble_world* world, size_t index,
                                                          size_t piece, rubble_outcome_piece* out);

/// A live object.
typedef struct rubble_object_info {
    uint32_t id;                 ///< its id
    uint32_t version;            ///< bumped when its shape changes
    int destructible;            ///< 0 when it never breaks
    rubble_mass_properties mass; ///< mass properties of its mesh (density 1; pieces are centred at 0 but
                                 ///< for a large remainder that keeps its parent's frame)
    double density;              ///< its density
    size_t triangle_count;       ///< triangles of its mesh
    size_t convex_part_count;    ///< its convex collision parts
} rubble_object_info;

/// Number of live objects.
RUBBLE_C_API rubble_status rubble_world_object_count(const rubble_world* world, size_t* count);
/// A live object; RUBBLE_ERROR_INVALID_ARGUMENT when there is none with this id.
RUBBLE_C_API rubble_status rubble_world_get_object(const rubble_world* world, uint32_t id,
                                                   rubble_object_info* out);
/// A copy of an object's mesh (in its own coordinates), to destroy with rubble_mesh_destroy.
RUBBLE_C_API rubble_status rubble_world_copy_object_mesh(const rubble_world* world, uint32_t id,
                                                         rubble_mesh** out);
/// The corner points of an object's convex part, as rubble_fracture_get_convex_part.
RUBBLE_C_API rubble_status rubble_world_get_convex_part(const rubble_world* world, uint32_t id, size_t part,
                                                        double* points, size_t capacity, size_t* count);

/// A structure without a physics engine (rubble/runtime/Structure.hpp): static bodies bonded where they touch,
/// solved under gravity, loads and impact damage at every step; the bonds that break and the bodies that fall
/// come back as records, for the caller's engine to let fall and for effects (dust, sound).
typedef struct rubble_structure rubble_structure;

/// Settings of a structure; rubble_structure_config_init sets the defaults.
typedef struct rubble_structure_config {
    double bearing_friction;   ///< > 0: bodies rest on each other with this friction coefficient; 0: welded
    int converged;             ///< 1: every step solves to a relative residual of 1e-3; 0: a sweep budget
    double damage_radius;      ///< impacts weaken the bonds within this distance (m) of the hit
    double damage_per_impulse; ///< health a bond at the hit loses per N*s of impulse
} rubble_structure_config;

/// What one step did; its records stay readable until the next step.
typedef struct rubble_structure_step_info {
    size_t break_count;    ///< bonds broken
    size_t collapse_count; ///< bodies that lost their support (they left the structure)
    double residual;       ///< relative residual of the step's last solve
} rubble_structure_step_info;

/// A bond that broke.
typedef struct rubble_structure_break {
    uint64_t step;          ///< the step it broke in (1 for the first)
    uint32_t a, b;          ///< the bodies it joined, a < b
    double position[3];     ///< interface centroid (world)
    double normal[3];       ///< interface normal, from a to b
    double area;            ///< interface area (m^2)
    double force[3];        ///< the force it carried the moment it broke, b on a (N)
    double utilisation;     ///< its largest stress over its limit (> 1 when its load broke it)
    int damaged;            ///< 1: impact damage broke it, not its load
    const char* material_a; ///< a's material; valid until the next step
    const char* material_b; ///< b's material; valid until the next step
} rubble_structure_break;

/// A body that lost its support.
typedef struct rubble_structure_collapse {
    uint64_t step;        ///< the step it fell in
    uint32_t body;        ///< its id
    double position[3];   ///< its centre of mass (world)
    double volume, mass;  ///< m^3, kg
    const char* material; ///< its material; valid until the next step
} rubble_structure_collapse;

/// The defaults: bearings with friction 0.6, converged solves, damage within 1 m at 1e-4 per N*s.
RUBBLE_C_API rubble_status rubble_structure_config_init(rubble_structure_config* config);
/// Creates a structure (NULL config means the defaults).
RUBBLE_C_API rubble_status rubble_structure_create(const rubble_structure_config* config,
                                                   rubble_structure** out);
/// Destroys a structure (NULL is accepted and ignored).
RUBBLE_C_API rubble_status rubble_structure_destroy(rubble_structure* structure);
/// Adds a body (or replaces the one with this id, > 0): a closed mesh (its convex parts) placed by a rotation
/// (row-major, NULL: none) and a translation, of a material preset (NULL or "": concrete); root = 1 holds it
/// (the ground). RUBBLE_ERROR_INVALID_INPUT, changing nothing, for an unknown material or a bad mesh.
RUBBLE_C_API rubble_status rubble_structure_add(rubble_structure* structure, uint32_t id, const rubble_mesh* mesh,
                                                const double rotation[9], const double translation[3],
                                                const char* material, int root);
/// Removes a body and its bonds; RUBBLE_ERROR_INVALID_ARGUMENT when there is none with this id.
RUBBLE_C_API rubble_status rubble_structure_remove(rubble_structure* structure, uint32_t id);
/// A force (N) at a world point on a body for the next step (a contact, a weight).
RUBBLE_C_API rubble_status rubble_structure_add_load(rubble_structure* structure, uint32_t id,
                                                     const double force[3], const double point[3]);
/// Weakens the bonds near a hit (world point, impulse in N*s) at the next step.
RUBBLE_C_API rubble_status rubble_structure_damage(rubble_structure* structure, const double point[3],
                                                   double impulse);
/// Solves under gravity (m/s^2; NULL: 9.81 down y), breaks overstressed bonds and lets go of what they held.
RUBBLE_C_API rubble_status rubble_structure_step(rubble_structure* structure, const double gravity[3],
                                                 rubble_structure_step_info* info);
/// Break `index` of the latest step.
RUBBLE_C_API rubble_status rubble_structure_get_break(const rubble_structure* structure, size_t index,
                                                      rubble_structure_break* out);
/// Collapse `index` of the latest step.
RUBBLE_C_API rubble_status rubble_structure_get_collapse(const rubble_structure* structure, size_t index,
                                                         rubble_structure_collapse* out);
/// Number of bodies and of intact bonds.
RUBBLE_C_API rubble_status rubble_structure_count(const rubble_structure* structure, size_t* bodies,
                                                  size_t* bonds);

#ifdef __cplusplus
}
#endif

#endif
