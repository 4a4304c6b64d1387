/* The C API (rubble/rubble.h) from C11: every function, its results and its error paths. Exits non-zero
 * naming every failed check. Built as C and linked against librubble.so; CI runs it under ASan+UBSan too.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rubble/core/Version.hpp"
#include "rubble/rubble.h"

static int failures = 0;

#define CHECK(cond)                                                                                          \
    do {                                                                                                     \
        if (!(cond)) {                                                                                       \
            fprintf(stderr, "%s:%d: check failed: %s (last error: %s)\n", __FILE__, __LINE__, #cond,         \
                    rubble_last_error());                                                                    \
            ++failures;                                                                                      \
        }                                                                                                    \
    } while (0)

#define CHECK_OK(call) CHECK((call) == RUBBLE_OK)

static int contains(const char* text, const char* part) {
    return strstr(text, part) != NULL;
}

static int log_calls = 0;
static void count_log(int level, const char* message, void* user) {
    (void)message;
    if (level == 1 && user == &log_calls)
        ++log_calls;
}

static void test_status_and_version(void) {
    CHECK(rubble_api_version() == RUBBLE_C_API_VERSION);
    CHECK(strcmp(rubble_version(), RUBBLE_VERSION_STRING) == 0);
    CHECK(strcmp(rubble_status_name(RUBBLE_OK), "ok") == 0);
    CHECK(strcmp(rubble_status_name(RUBBLE_ERROR_INVALID_INPUT), "invalid input") == 0);
    CHECK(strcmp(rubble_status_name(RUBBLE_ERROR_INVALID_ARGUMENT), "invalid argument") == 0);
    CHECK(strcmp(rubble_status_name((rubble_status)12345), "unknown status") == 0);
}

/* Null arguments give RUBBLE_ERROR_INVALID_ARGUMENT with a message naming the function, never a crash. */
static void test_null_arguments(void) {
    rubble_mesh* mesh = NULL;
    rubble_mesh_data data;
    rubble_mesh_report report;
    rubble_fracture_info info;
    rubble_piece piece;
    rubble_impact impact = {{0, 1, 0}, {0, 1, 0}, 10};
    size_t count = 0;
    uint32_t id = 0;
    CHECK(rubble_mesh_create(NULL, 3, NULL, 1, &mesh) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(mesh == NULL);
    CHECK(contains(rubble_last_error(), "rubble_mesh_create"));
    CHECK(rubble_mesh_create(NULL, 0, NULL, 0, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_create_box(NULL, NULL, 1, &mesh) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_read(NULL, &mesh) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_write_obj(NULL, "x.obj") == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_clone(NULL, &mesh) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_get_data(NULL, &data) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_check(NULL, &report) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_repair(NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_mass_properties(NULL, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_fracture_params_init(NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_fracture_mesh(NULL, &impact, NULL, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_fracture_get_info(NULL, &info) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_fracture_get_piece(NULL, 0, &piece) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_fracture_get_convex_part(NULL, 0, 0, NULL, 0, &count) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_config_init(NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_create(NULL, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_object_desc_init(NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_add_object(NULL, NULL, &id) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_remove_object(NULL, 1) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_submit_impact(NULL, 1, &impact, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_begin_frame(NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_wait_idle(NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_collect(NULL, &count) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_get_outcome(NULL, 0, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_get_outcome_piece(NULL, 0, 0, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_object_count(NULL, &count) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_get_object(NULL, 1, NULL) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_copy_object_mesh(NULL, 1, &mesh) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_get_convex_part(NULL, 1, 0, NULL, 0, &count) == RUBBLE_ERROR_INVALID_ARGUMENT);
    /* Destroying nothing is fine. */
    CHECK_OK(rubble_mesh_destroy(NULL));
    CHECK_OK(rubble_fracture_destroy(NULL));
    CHECK_OK(rubble_world_destroy(NULL));
    CHECK(strcmp(rubble_last_error(), "") == 0);
}

/* A handle of one kind passed where another is expected is refused by its tag. */
static void test_wrong_handles(void) {
    rubble_world* world = NULL;
    rubble_mesh_data data;
    CHECK_OK(rubble_world_create(NULL, &world));
    CHECK(rubble_mesh_get_data((const rubble_mesh*)(const void*)world, &data) ==
          RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_destroy((rubble_mesh*)(void*)world) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_fracture_destroy((rubble_fracture*)(void*)world) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rubble_world_destroy(world));
}

/* Meshes: build from arrays, read back, check, repair, mass properties, write and read an OBJ. */
static void test_meshes(const char* dir) {
    /* A tetrahedron, outward. */
    const double positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t indices[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    const uint32_t bad_indices[] = {0, 2, 1, 0, 1, 9};
    const double nan_positions[] = {0, 0, 0, 1, 0, 0, 0, NAN, 0};
    const uint32_t open_indices[] = {0, 2, 1, 0, 1, 3, 0, 3, 2}; /* one face missing */
    rubble_mesh* tet = NULL;
    rubble_mesh* open = NULL;
    rubble_mesh* flipped = NULL;
    rubble_mesh* bad = NULL;
    rubble_mesh* read_back = NULL;
    rubble_mesh_data data;
    rubble_mesh_report report;
    rubble_mass_properties mass;
    char path[1024];
    const uint32_t flipped_indices[] = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};

    CHECK_OK(rubble_mesh_create(positions, 4, indices, 4, &tet));
    CHECK_OK(rubble_mesh_get_data(tet, &data));
    CHECK(data.vertex_count == 4 && data.triangle_count == 4);
    CHECK(memcmp(data.positions, positions, sizeof positions) == 0);
    CHECK(memcmp(data.indices, indices, sizeof indices) == 0);
    CHECK(data.materials == NULL && data.uvs == NULL && data.normals == NULL);

    CHECK_OK(rubble_mesh_check(tet, &report));
    CHECK(report.valid && report.closed && report.manifold && report.oriented && report.outward);
    CHECK(report.problem_count == 0 && fabs(report.volume - 1.0 / 6) < 1e-12);
    CHECK_OK(rubble_mesh_mass_properties(tet, &mass));
    CHECK(fabs(mass.volume - 1.0 / 6) < 1e-12);
    CHECK(fabs(mass.center_of_mass[0] - 0.25) < 1e-12 && fabs(mass.center_of_mass[2] - 0.25) < 1e-12);
    CHECK(mass.principal_moments[0] > 0 && mass.principal_moments[0] <= mass.principal_moments[2]);
    CHECK(fabs(mass.inertia[1] - mass.inertia[3]) < 1e-15); /* symmetric */

    /* Bad input: an index out of range and a NaN coordinate are invalid input, with a message. */
    CHECK(rubble_mesh_create(positions, 4, bad_indices, 2, &bad) == RUBBLE_ERROR_INVALID_INPUT);
    CHECK(bad == NULL && strlen(rubble_last_error()) > 0);
    CHECK(rubble_mesh_create(nan_positions, 3, indices, 1, &bad) == RUBBLE_ERROR_INVALID_INPUT);
    CHECK(bad == NULL);

    /* An open mesh fails the check, which lists why, and the report is filled. */
    CHECK_OK(rubble_mesh_create(positions, 4, open_indices, 3, &open));
    CHECK(rubble_mesh_check(open, &report) == RUBBLE_ERROR_INVALID_INPUT);
    CHECK(!report.valid && !report.closed && report.boundary_edges == 3 && report.problem_count > 0);
    CHECK(contains(rubble_last_error(), "not a valid solid"));

    /* An inward mesh is repaired into an outward one. */
    CHECK_OK(rubble_mesh_create(positions, 4, flipped_indices, 4, &flipped));
    CHECK(rubble_mesh_check(flipped, &report) == RUBBLE_ERROR_INVALID_INPUT && !report.outward);
    CHECK_OK(rubble_mesh_repair(flipped));
    CHECK_OK(rubble_mesh_check(flipped, &report));
    CHECK(report.outward && fabs(report.volume - 1.0 / 6) < 1e-12);

    /* OBJ round trip keeps positions and triangles. */
    snprintf(path, sizeof path, "%s/capi_tet.obj", dir);
    CHECK_OK(rubble_mesh_write_obj(tet, path));
    CHECK_OK(rubble_mesh_read(path, &read_back));
    CHECK_OK(rubble_mesh_get_data(read_back, &data));
    CHECK(data.vertex_count == 4 && data.triangle_count == 4);
    if (data.vertex_count == 4)
        CHECK(memcmp(data.positions, positions, sizeof positions) == 0);

    /* Files: a missing file is an IO error naming it; an unknown extension is unsupported. */
    snprintf(path, sizeof path, "%s/does_not_exist.obj", dir);
    CHECK(rubble_mesh_read(path, &bad) == RUBBLE_ERROR_IO);
    CHECK(contains(rubble_last_error(), "does_not_exist.obj"));
    snprintf(path, sizeof path, "%s/mesh.xyz", dir);
    CHECK(rubble_mesh_read(path, &bad) == RUBBLE_ERROR_UNSUPPORTED);

    CHECK_OK(rubble_mesh_destroy(tet));
    CHECK_OK(rubble_mesh_destroy(open));
    CHECK_OK(rubble_mesh_destroy(flipped));
    CHECK_OK(rubble_mesh_destroy(read_back));
}

static double sum_piece_volumes(const rubble_fracture* fracture) {
    rubble_fracture_info info;
    rubble_piece piece;
    double total = 0;
    size_t i;
    if (rubble_fracture_get_info(fracture, &info) != RUBBLE_OK)
        return -1;
    for (i = 0; i < info.piece_count; ++i) {
        if (rubble_fracture_get_piece(fracture, i, &piece) != RUBBLE_OK)
            return -1;
        total += piece.mass.volume;
    }
    return total + info.dropped_volume;
}

/* Fracture: pieces that conserve volume, are closed, carry cut materials and convex parts; determinism. */
static void test_fracture(void) {
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    rubble_mesh* cube = NULL;
    rubble_mesh* copy = NULL;
    rubble_fracture* broken = NULL;
    rubble_fracture* again = NULL;
    rubble_fracture* shattered = NULL;
    rubble_fracture* missed = NULL;
    rubble_fracture_params params;
    rubble_fracture_info info;
    rubble_piece piece, piece_again;
    rubble_mesh_data data, data_again;
    rubble_mesh_report report;
    rubble_impact impact = {{0.3, 1.0, 0.2}, {0, 1, 0}, 40};
    rubble_impact far_away = {{50, 50, 50}, {0, 1, 0}, 1};
    double points[3 * 64];
    size_t count = 0, i, p, interior = 0, remainder = 0, debris = 0;

    CHECK(rubble_mesh_create_box(lo, hi, 0, &cube) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_create_box(hi, lo, 2, &cube) == RUBBLE_ERROR_INVALID_INPUT);
    CHECK_OK(rubble_mesh_create_box(lo, hi, 7, &cube));
    CHECK_OK(rubble_mesh_get_data(cube, &data));
    CHECK(data.triangle_count == 12 * 49);

    CHECK_OK(rubble_fracture_params_init(&params));
    CHECK(params.pattern == RUBBLE_PATTERN_SINGLE_CELL && params.backend == RUBBLE_BACKEND_FAST);
    CHECK(params.convex_parts == 1 && params.max_convex_parts >= 1 && params.cells >= 1);
    params.seed = 7;
    CHECK_OK(rubble_fracture_mesh(cube, &impact, &params, &broken));
    CHECK_OK(rubble_fracture_get_info(broken, &info));
    CHECK(info.piece_count >= 2 && fabs(info.input_volume - 8) < 1e-9 && info.total_ms >= 0);
    CHECK(fabs(sum_piece_volumes(broken) - info.input_volume) < 1e-9 * info.input_volume);
    for (i = 0; i < info.piece_count; ++i) {
        CHECK_OK(rubble_fracture_get_piece(broken, i, &piece));
        CHECK(piece.mass.volume > 0 && piece.convex_part_count >= 1);
        /* The parts' concavity: a fraction of the piece's diagonal, measured (not -1). */
        CHECK(piece.concavity >= 0 && piece.concavity < 0.5);
        if (piece.cell < 0)
            ++remainder;
        else
            ++debris;
        CHECK_OK(rubble_mesh_check(piece.mesh, &report));
        CHECK(report.valid && fabs(report.volume - piece.mass.volume) < 1e-9);
        CHECK_OK(rubble_mesh_get_data(piece.mesh, &data));
        CHECK(data.materials != NULL && data.uvs != NULL);
        for (p = 0; data.materials && p < data.triangle_count; ++p)
            interior += data.materials[p] == RUBBLE_INTERIOR_MATERIAL;
        /* Convex parts: ask for the count, then read them; every point lies within the cube. */
        for (p = 0; p < piece.convex_part_count; ++p) {
            size_t k;
            CHECK_OK(rubble_fracture_get_convex_part(broken, i, p, NULL, 0, &count));
            CHECK(count >= 4 && count <= 64);
            CHECK_OK(rubble_fracture_get_convex_part(broken, i, p, points, 64, &count));
            for (k = 0; k < count && k < 64; ++k)
                CHECK(fabs(points[3 * k]) <= 1 + 1e-9 && fabs(points[3 * k + 1]) <= 1 + 1e-9 &&
                      fabs(points[3 * k + 2]) <= 1 + 1e-9);
        }
        CHECK(rubble_fracture_get_convex_part(broken, i, piece.convex_part_count, points, 64, &count) ==
              RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(rubble_fracture_get_convex_part(broken, i, 0, NULL, 5, &count) ==
              RUBBLE_ERROR_INVALID_ARGUMENT);
    }
    CHECK(remainder >= 1 && debris >= 1 && interior > 0);
    CHECK(rubble_fracture_get_piece(broken, info.piece_count, &piece) == RUBBLE_ERROR_INVALID_ARGUMENT);

    /* A piece mesh belongs to its fracture: it cannot be destroyed or repaired, but cloned. */
    CHECK_OK(rubble_fracture_get_piece(broken, 0, &piece));
    CHECK(rubble_mesh_destroy((rubble_mesh*)piece.mesh) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_mesh_repair((rubble_mesh*)piece.mesh) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rubble_mesh_clone(piece.mesh, &copy));

    /* Same seed, same pieces (byte for byte). */
    CHECK_OK(rubble_fracture_mesh(cube, &impact, &params, &again));
    CHECK_OK(rubble_fracture_get_piece(again, 0, &piece_again));
    CHECK_OK(rubble_mesh_get_data(piece.mesh, &data));
    CHECK_OK(rubble_mesh_get_data(piece_again.mesh, &data_again));
    CHECK(data.vertex_count == data_again.vertex_count && data.triangle_count == data_again.triangle_count);
    if (data.vertex_count == data_again.vertex_count)
        CHECK(memcmp(data.positions, data_again.positions, 3 * sizeof(double) * data.vertex_count) == 0);

    /* A shatter pattern with the exact backend, without convex parts. */
    params.pattern = RUBBLE_PATTERN_SHATTER;
    params.cells = 4;
    params.backend = RUBBLE_BACKEND_COREFINE;
    params.convex_parts = 0;
    CHECK_OK(rubble_fracture_mesh(cube, &impact, &params, &shattered));
    CHECK_OK(rubble_fracture_get_info(shattered, &info));
    CHECK(info.piece_count >= 3);
    CHECK(fabs(sum_piece_volumes(shattered) - 8) < 1e-9 * 8);
    CHECK_OK(rubble_fracture_get_piece(shattered, 0, &piece));
    CHECK(piece.convex_part_count == 0 && piece.concavity == -1);

    /* Adaptive: a weak hit chips one cell, a strong one shatters into `cells`. */
    {
        rubble_fracture *chip = NULL, *burst = NULL;
        rubble_fracture_info chip_info, burst_info;
        rubble_impact weak = impact, strong = impact;
        weak.impulse = 10;
        strong.impulse = 2000;
        params.pattern = RUBBLE_PATTERN_ADAPTIVE;
        params.cells = 8;
        params.backend = RUBBLE_BACKEND_FAST;
        CHECK_OK(rubble_fracture_mesh(cube, &weak, &params, &chip));
        CHECK_OK(rubble_fracture_mesh(cube, &strong, &params, &burst));
        CHECK_OK(rubble_fracture_get_info(chip, &chip_info));
        CHECK_OK(rubble_fracture_get_info(burst, &burst_info));
        CHECK(chip_info.piece_count <= 3);
        CHECK(burst_info.piece_count >= 4 && burst_info.piece_count > chip_info.piece_count);
        CHECK(fabs(sum_piece_volumes(chip) - 8) < 1e-9 * 8);
        CHECK(fabs(sum_piece_volumes(burst) - 8) < 1e-9 * 8);
        CHECK_OK(rubble_fracture_destroy(chip));
        CHECK_OK(rubble_fracture_destroy(burst));
        params.pattern = RUBBLE_PATTERN_SHATTER;
        params.cells = 4;
        params.backend = RUBBLE_BACKEND_COREFINE;
    }

    /* Rough cut faces: a material's preset, or set by hand; still closed, with the volume kept; a bad
       value or material is refused, naming it. */
    {
        rubble_fracture* rough = NULL;
        rubble_fracture_params rp;
        rubble_fracture_info rough_info;
        size_t k, flat_triangles = 0, rough_triangles = 0;
        CHECK_OK(rubble_fracture_params_init(&rp));
        CHECK(rp.material == NULL && rp.roughness < 0 && rp.hurst < 0 && rp.feature_size < 0);
        rp.seed = 7;
        rp.convex_parts = 0;
        rp.material = "concrete";
        CHECK_OK(rubble_fracture_mesh(cube, &impact, &rp, &rough));
        CHECK_OK(rubble_fracture_get_info(rough, &rough_info));
        CHECK(fabs(sum_piece_volumes(rough) - 8) < 1e-9 * 8);
        for (k = 0; k < rough_info.piece_count; ++k) {
            CHECK_OK(rubble_fracture_get_piece(rough, k, &piece));
            CHECK_OK(rubble_mesh_check(piece.mesh, &report));
            CHECK(report.valid);
            CHECK_OK(rubble_mesh_get_data(piece.mesh, &data));
            rough_triangles += data.triangle_count;
        }
        CHECK_OK(rubble_fracture_destroy(rough));
        rough = NULL;
        rp.roughness = 0; /* flat, as without a material */
        CHECK_OK(rubble_fracture_mesh(cube, &impact, &rp, &rough));
        CHECK_OK(rubble_fracture_get_info(rough, &rough_info));
        for (k = 0; k < rough_info.piece_count; ++k) {
            CHECK_OK(rubble_fracture_get_piece(rough, k, &piece));
            CHECK_OK(rubble_mesh_get_data(piece.mesh, &data));
            flat_triangles += data.triangle_count;
        }
        CHECK(rough_triangles > flat_triangles);
        CHECK_OK(rubble_fracture_destroy(rough));
        rp.roughness = 0.1;
        rp.hurst = 1.5;
        CHECK(rubble_fracture_mesh(cube, &impact, &rp, &rough) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(contains(rubble_last_error(), "hurst"));
        rp.hurst = -1;
        rp.material = "cheese";
        CHECK(rubble_fracture_mesh(cube, &impact, &rp, &rough) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(contains(rubble_last_error(), "cheese"));
    }

    /* Errors: bad parameters, an impact whose cells miss the mesh, an open mesh. */
    params.cells = 0;
    CHECK(rubble_fracture_mesh(cube, &impact, &params, &missed) == RUBBLE_ERROR_INVALID_ARGUMENT);
    params.cells = 4;
    params.backend = (rubble_backend)9;
    CHECK(rubble_fracture_mesh(cube, &impact, &params, &missed) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(contains(rubble_last_error(), "backend"));
    params.backend = RUBBLE_BACKEND_FAST;
    params.pattern = (rubble_pattern)-3;
    CHECK(rubble_fracture_mesh(cube, &impact, &params, &missed) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(contains(rubble_last_error(), "pattern"));
    params.pattern = RUBBLE_PATTERN_SHATTER;
    CHECK(rubble_fracture_mesh(cube, &far_away, NULL, &missed) == RUBBLE_ERROR_NO_INTERSECTION);
    CHECK(missed == NULL);
    {
        const double positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
        const uint32_t open_indices[] = {0, 2, 1, 0, 1, 3, 0, 3, 2};
        rubble_mesh* open = NULL;
        rubble_impact hit = {{0.1, 0.1, 0.1}, {0, 0, -1}, 10};
        CHECK_OK(rubble_mesh_create(positions, 4, open_indices, 3, &open));
        CHECK(rubble_fracture_mesh(open, &hit, NULL, &missed) == RUBBLE_ERROR_INVALID_INPUT);
        CHECK(missed == NULL && strlen(rubble_last_error()) > 0);
        CHECK_OK(rubble_mesh_destroy(open));
    }

    CHECK_OK(rubble_fracture_destroy(broken));
    CHECK_OK(rubble_fracture_destroy(again));
    CHECK_OK(rubble_fracture_destroy(shattered));
    /* The clone outlives its fracture. */
    CHECK_OK(rubble_mesh_check(copy, &report));
    CHECK(report.valid);
    CHECK_OK(rubble_mesh_destroy(copy));
    CHECK_OK(rubble_mesh_destroy(cube));
}

/* The world: add, impact, collect; the parent is replaced by pieces whose volumes add up. */
static void test_world(void) {
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    rubble_world_config config;
    rubble_world* world = NULL;
    rubble_mesh* cube = NULL;
    rubble_mesh* piece_mesh = NULL;
    rubble_object_desc desc;
    rubble_object_info object;
    rubble_outcome outcome;
    rubble_outcome_piece piece;
    rubble_mesh_report report;
    rubble_impact impact = {{0.3, 1.0, 0.2}, {0, 1, 0}, 40};
    rubble_impact weak = {{0.3, 1.0, 0.2}, {0, 1, 0}, 5};
    uint32_t id = 0, other = 0;
    size_t outcomes = 0, count = 0, i;
    int accepted = -1;
    double volume = 0, points[3 * 256];

    CHECK_OK(rubble_world_config_init(&config));
    CHECK(config.workers == -1 && config.deterministic == 0);
    config.workers = 0;
    CHECK(rubble_world_create(&config, &world) == RUBBLE_ERROR_INVALID_ARGUMENT && world == NULL);
    config.workers = 2;
    config.seed = 5;
    CHECK_OK(rubble_world_create(&config, &world));

    CHECK_OK(rubble_object_desc_init(&desc));
    CHECK(desc.mesh == NULL && desc.density == 1 && desc.destructible == 1);
    CHECK(rubble_world_add_object(world, &desc, &id) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rubble_mesh_create_box(lo, hi, 7, &cube));
    desc.mesh = cube;
    desc.density = 0;
    CHECK(rubble_world_add_object(world, &desc, &id) == RUBBLE_ERROR_INVALID_ARGUMENT);
    desc.density = 2;
    desc.impulse_threshold = 10;
    CHECK_OK(rubble_world_add_object(world, &desc, &id));
    CHECK_OK(rubble_world_add_object(world, &desc, &other));
    CHECK(id != other);
    CHECK_OK(rubble_world_object_count(world, &count));
    CHECK(count == 2);
    CHECK_OK(rubble_world_get_object(world, id, &object));
    CHECK(object.id == id && object.destructible && object.density == 2 && object.convex_part_count >= 1);
    CHECK(fabs(object.mass.volume - 8) < 1e-9 && object.triangle_count == 12 * 49);
    CHECK_OK(rubble_world_get_convex_part(world, id, 0, points, 256, &count));
    CHECK(count >= 4);
    CHECK(rubble_world_get_convex_part(world, id, object.convex_part_count, points, 256, &count) ==
          RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_get_object(world, 999, &object) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_remove_object(world, 999) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rubble_world_remove_object(world, other));
    CHECK(rubble_world_get_object(world, other, &object) == RUBBLE_ERROR_INVALID_ARGUMENT);

    /* Below the threshold or on an unknown object: ignored, not an error. */
    CHECK_OK(rubble_world_submit_impact(world, id, &weak, &accepted));
    CHECK(accepted == 0);
    CHECK_OK(rubble_world_submit_impact(world, 999, &impact, &accepted));
    CHECK(accepted == 0);
    CHECK_OK(rubble_world_submit_impact(world, id, &impact, &accepted));
    CHECK(accepted == 1);
    CHECK_OK(rubble_world_wait_idle(world));
    CHECK_OK(rubble_world_begin_frame(world));
    CHECK_OK(rubble_world_collect(world, &outcomes));
    CHECK(outcomes == 1);
    CHECK_OK(rubble_world_get_outcome(world, 0, &outcome));
    CHECK(outcome.parent == id && outcome.piece_count >= 2);
    CHECK(fabs(outcome.impulse - impact.impulse) < 1e-3 * impact.impulse); /* the impact that broke it */
    CHECK(rubble_world_get_outcome(world, 1, &outcome) == RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(rubble_world_get_object(world, id, &object) == RUBBLE_ERROR_INVALID_ARGUMENT); /* replaced */
    volume = outcome.dropped_volume;
    for (i = 0; i < outcome.piece_count; ++i) {
        CHECK_OK(rubble_world_get_outcome_piece(world, 0, i, &piece));
        CHECK_OK(rubble_world_get_object(world, piece.id, &object));
        CHECK(object.mass.volume > 0 && object.convex_part_count >= 1 && object.density == 2);
        /* A piece's mesh is centred at its centre of mass; its frame puts it back into the parent. */
        CHECK(fabs(object.mass.center_of_mass[0]) < 1e-9 && fabs(object.mass.center_of_mass[1]) < 1e-9);
        CHECK(fabs(piece.translation[0]) <= 1 && fabs(piece.translation[1]) <= 1);
        CHECK(fabs(piece.rotation[0] * piece.rotation[0] + piece.rotation[3] * piece.rotation[3] +
                   piece.rotation[6] * piece.rotation[6] - 1) < 1e-9);
        volume += object.mass.volume;
        CHECK_OK(rubble_world_copy_object_mesh(world, piece.id, &piece_mesh));
        CHECK_OK(rubble_mesh_check(piece_mesh, &report));
        CHECK(report.valid);
        CHECK_OK(rubble_mesh_destroy(piece_mesh));
        piece_mesh = NULL;
    }
    CHECK(rubble_world_get_outcome_piece(world, 0, outcome.piece_count, &piece) ==
          RUBBLE_ERROR_INVALID_ARGUMENT);
    CHECK(fabs(volume - 8) < 1e-6);
    /* The next collect has nothing new and forgets the old outcomes. */
    CHECK_OK(rubble_world_begin_frame(world));
    CHECK_OK(rubble_world_collect(world, &outcomes));
    CHECK(outcomes == 0);
    CHECK(rubble_world_get_outcome(world, 0, &outcome) == RUBBLE_ERROR_INVALID_ARGUMENT);

    CHECK_OK(rubble_world_destroy(world));
    CHECK_OK(rubble_mesh_destroy(cube));
}

/* Log messages reach the callback (an open mesh added to a world is repaired or made indestructible, with a
 * warning), and NULL restores the default. The mesh is two faces of a tetrahedron: its hole is not planar, so
 * repair cannot close it. */
static void test_log_callback(void) {
    const double positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t open_indices[] = {0, 2, 1, 0, 1, 3};
    rubble_world* world = NULL;
    rubble_mesh* open = NULL;
    rubble_object_desc desc;
    rubble_object_info info;
    uint32_t id = 0;
    CHECK_OK(rubble_set_log_callback(count_log, &log_calls));
    CHECK_OK(rubble_world_create(NULL, &world));
    CHECK_OK(rubble_mesh_create(positions, 4, open_indices, 2, &open));
    CHECK_OK(rubble_object_desc_init(&desc));
    desc.mesh = open;
    CHECK_OK(rubble_world_add_object(world, &desc, &id));
    CHECK_OK(rubble_world_get_object(world, id, &info));
    CHECK(info.destructible == 0);
    CHECK(log_calls == 1);
    CHECK_OK(rubble_set_log_callback(NULL, NULL));
    CHECK_OK(rubble_world_destroy(world));
    CHECK_OK(rubble_mesh_destroy(open));
}

/* Reads "x,y,z" (or one number) into v; returns how many numbers were read. */
static int read_numbers(const char* text, double* v, int most) {
    int n = 0;
    char* end = NULL;
    while (n < most) {
        v[n++] = strtod(text, &end);
        if (*end != ',')
            break;
        text = end + 1;
    }
    return n;
}

/* One row of tests/data/parameter_cases.tsv through the C API: RUBBLE_OK, or an invalid argument whose
 * message contains the row's message. */
static void check_parameter_case(const char* name, const char* value, const char* message) {
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    double v[3] = {0, 0, 0};
    rubble_mesh* cube = NULL;
    rubble_status status;
    char error[512];
    const int expect_ok = strcmp(message, "ok") == 0;
    read_numbers(value, v, 3);
    CHECK_OK(rubble_mesh_create_box(lo, hi, 1, &cube));
    if (strcmp(name, "density") == 0) {
        rubble_world* world = NULL;
        rubble_object_desc desc;
        uint32_t id = 0;
        CHECK_OK(rubble_world_create(NULL, &world));
        CHECK_OK(rubble_object_desc_init(&desc));
        desc.mesh = cube;
        desc.density = v[0];
        status = rubble_world_add_object(world, &desc, &id);
        snprintf(error, sizeof error, "%s", rubble_last_error());
        CHECK_OK(rubble_world_destroy(world));
    } else {
        rubble_impact impact = {{0.5, 0.5, 1}, {0, 0, 1}, 100};
        rubble_fracture_params params;
        rubble_fracture* broken = NULL;
        CHECK_OK(rubble_fracture_params_init(&params));
        params.convex_parts = 0;
        if (strcmp(name, "impulse") == 0) {
            impact.impulse = v[0];
        } else if (strcmp(name, "normal") == 0) {
            memcpy(impact.normal, v, sizeof v);
        } else if (strcmp(name, "point") == 0) {
            memcpy(impact.point, v, sizeof v);
        } else if (strcmp(name, "cells") == 0) {
            params.pattern = RUBBLE_PATTERN_SHATTER;
            params.cells = (int)v[0];
        } else if (strcmp(name, "roughness") == 0) {
            params.roughness = v[0];
        } else if (strcmp(name, "hurst") == 0) {
            params.roughness = 0.1;
            params.hurst = v[0];
        } else if (strcmp(name, "feature_size") == 0) {
            params.roughness = 0.1;
            params.feature_size = v[0];
        } else if (strcmp(name, "max_parts") == 0) {
            params.max_convex_parts = (int)v[0];
        } else {
            fprintf(stderr, "no C case for %s\n", name);
            ++failures;
        }
        status = rubble_fracture_mesh(cube, &impact, &params, &broken);
        snprintf(error, sizeof error, "%s", rubble_last_error());
        CHECK_OK(rubble_fracture_destroy(broken));
    }
    if (expect_ok ? status != RUBBLE_OK
                  : status != RUBBLE_ERROR_INVALID_ARGUMENT || !contains(error, message)) {
        fprintf(stderr, "parameter case %s %s: status %d, message '%s', expected '%s'\n", name, value,
                (int)status, error, message);
        ++failures;
    }
    CHECK_OK(rubble_mesh_destroy(cube));
}

/* True when the comma-separated list faces holds face. */
static int has_face(const char* faces, const char* face) {
    const size_t len = strlen(face);
    for (const char* p = faces; p; p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL)
        if (strncmp(p, face, len) == 0 && (p[len] == ',' || p[len] == '\0'))
            return 1;
    return 0;
}

/* The C face of the shared parameter table: every row the C API can express. */
static void test_parameter_table(const char* path) {
    char line[512];
    int rows = 0;
    FILE* f = fopen(path, "r");
    CHECK(f != NULL);
    if (!f)
        return;
    while (fgets(line, sizeof line, f)) {
        char* fields[4];
        int n = 0;
        char* p = line;
        line[strcspn(line, "\n")] = '\0';
        if (line[0] == '#' || line[0] == '\0')
            continue;
        while (n < 4) {
            fields[n++] = p;
            p = strchr(p, '\t');
            if (!p)
                break;
            *p++ = '\0';
        }
        CHECK(n == 4);
        if (n == 4 && has_face(fields[0], "c")) {
            check_parameter_case(fields[1], fields[2], fields[3]);
            ++rows;
        }
    }
    fclose(f);
    CHECK(rows >= 15);
}

/* A structure without an engine: a cantilever welded to a held wall stands or breaks as its root bending
 * stress 3 rho g L^2 / h says (concrete's tensile limit 2.9 MPa is passed between 2.5 and 3.5 m); the break and
 * the collapse come back as records; bad bodies are refused and change nothing. */
static int cantilever(double span, const char* material, rubble_structure** out) {
    rubble_structure_config config;
    rubble_mesh *wall = NULL, *slab = NULL;
    const double wall_lo[3] = {-1, 0, -2}, wall_hi[3] = {0, 4, 2};
    const double slab_lo[3] = {0, 2, -0.75}, slab_hi[3] = {span, 2.2, 0.75}, zero[3] = {0, 0, 0};
    int ok = 1;
    CHECK_OK(rubble_structure_config_init(&config));
    config.bearing_friction = 0; /* welded */
    ok &= rubble_structure_create(&config, out) == RUBBLE_OK;
    ok &= rubble_mesh_create_box(wall_lo, wall_hi, 1, &wall) == RUBBLE_OK;
    ok &= rubble_mesh_create_box(slab_lo, slab_hi, 1, &slab) == RUBBLE_OK;
    ok &= rubble_structure_add(*out, 1, wall, NULL, zero, material, 1) == RUBBLE_OK;
    ok &= rubble_structure_add(*out, 2, slab, NULL, zero, material, 0) == RUBBLE_OK;
    CHECK_OK(rubble_mesh_destroy(wall));
    CHECK_OK(rubble_mesh_destroy(slab));
    CHECK(ok);
    return ok;
}

static void test_structure(void) {
    rubble_structure* s = NULL;
    rubble_structure_step_info info;
    rubble_structure_break k;
    rubble_structure_collapse c;
    size_t bodies = 0, bonds = 0;
    const double zero[3] = {0, 0, 0}, lo[3] = {3, 0, 0}, hi[3] = {4, 1, 1};
    const double skew[9] = {1, 0, 0, 0, 1, 0, 0, 0, 2}, down[3] = {0, -1, 0}, nan3[3] = {0, NAN, 0};
    const double light[3] = {0, -5e5, 0}, heavy[3] = {0, -1.2e6, 0}, tip[3] = {3.5, 2.2, 0};
    rubble_mesh* cube = NULL;
    if (cantilever(2.5, "concrete", &s)) {
        CHECK_OK(rubble_structure_count(s, &bodies, &bonds));
        CHECK(bodies == 2 && bonds == 1);
        CHECK_OK(rubble_structure_step(s, NULL, &info));
        CHECK(info.break_count == 0 && info.collapse_count == 0 && info.residual <= 1e-3);
        CHECK(rubble_structure_get_break(s, 0, &k) == RUBBLE_ERROR_INVALID_ARGUMENT);
        /* bad bodies change nothing */
        CHECK_OK(rubble_mesh_create_box(lo, hi, 1, &cube));
        CHECK(rubble_structure_add(s, 3, cube, NULL, zero, "Wood", 0) == RUBBLE_ERROR_INVALID_INPUT);
        CHECK(contains(rubble_last_error(), "unknown material 'Wood'"));
        CHECK(rubble_structure_add(s, 3, cube, skew, zero, "wood", 0) == RUBBLE_ERROR_INVALID_INPUT);
        CHECK(contains(rubble_last_error(), "not a rigid motion"));
        CHECK(rubble_structure_add(s, 0, cube, NULL, zero, "wood", 0) == RUBBLE_ERROR_INVALID_INPUT);
        CHECK(rubble_structure_add(s, 3, NULL, NULL, zero, "wood", 0) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(rubble_structure_add_load(s, 3, down, zero) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(rubble_structure_add_load(s, 2, nan3, zero) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(rubble_structure_damage(s, zero, -1) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(rubble_structure_remove(s, 3) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK_OK(rubble_structure_count(s, &bodies, &bonds));
        CHECK(bodies == 2 && bonds == 1);
        CHECK(rubble_structure_destroy((rubble_structure*)(void*)cube) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK(rubble_mesh_destroy((rubble_mesh*)(void*)s) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK_OK(rubble_mesh_destroy(cube));
        CHECK_OK(rubble_structure_destroy(s));
    }
    s = NULL;
    if (cantilever(3.5, "concrete", &s)) {
        CHECK_OK(rubble_structure_step(s, NULL, &info));
        CHECK(info.break_count == 1 && info.collapse_count == 1);
        CHECK_OK(rubble_structure_get_break(s, 0, &k));
        CHECK(k.step == 1 && k.a == 1 && k.b == 2 && !k.damaged && k.utilisation > 1);
        CHECK(fabs(k.position[0]) < 1e-9 && fabs(k.position[1] - 2.1) < 1e-9 && fabs(k.position[2]) < 1e-9);
        CHECK(fabs(k.area - 0.3) < 1e-9);
        CHECK(strcmp(k.material_a, "concrete") == 0 && strcmp(k.material_b, "concrete") == 0);
        CHECK_OK(rubble_structure_get_collapse(s, 0, &c));
        CHECK(c.step == 1 && c.body == 2 && strcmp(c.material, "concrete") == 0);
        CHECK(fabs(c.volume - 3.5 * 1.5 * 0.2) < 1e-9 && fabs(c.mass - 2400 * c.volume) < 1e-6);
        CHECK(fabs(c.position[0] - 1.75) < 1e-9 && fabs(c.position[1] - 2.1) < 1e-9);
        CHECK(rubble_structure_get_collapse(s, 1, &c) == RUBBLE_ERROR_INVALID_ARGUMENT);
        CHECK_OK(rubble_structure_count(s, &bodies, &bonds));
        CHECK(bodies == 1 && bonds == 0);
        CHECK_OK(rubble_structure_destroy(s));
    }
    s = NULL;
    if (cantilever(3.5, "steel", &s)) { /* 14 MPa against 355 */
        CHECK_OK(rubble_structure_step(s, NULL, &info));
        CHECK(info.break_count == 0 && info.collapse_count == 0);
        /* a tip load: 350 Pa per N at the root beside the slab's own 14 MPa */
        CHECK_OK(rubble_structure_add_load(s, 2, light, tip));
        CHECK_OK(rubble_structure_step(s, NULL, &info));
        CHECK(info.break_count == 0 && info.collapse_count == 0); /* 189 MPa */
        CHECK_OK(rubble_structure_add_load(s, 2, heavy, tip));
        CHECK_OK(rubble_structure_step(s, NULL, &info));
        CHECK(info.break_count == 1 && info.collapse_count == 1); /* 434 MPa */
        CHECK_OK(rubble_structure_destroy(s));
    }
    CHECK_OK(rubble_structure_destroy(NULL));
}

int main(int argc, char** argv) {
    const char* dir = argc > 1 ? argv[1] : ".";
    test_status_and_version();
    test_null_arguments();
    test_wrong_handles();
    test_meshes(dir);
    test_fracture();
    test_world();
    test_structure();
    test_log_callback();
    if (argc > 2)
        test_parameter_table(argv[2]);
    if (failures) {
        fprintf(stderr, "%d checks failed\n", failures);
        return 1;
    }
    printf("C API: all checks passed\n");
    return 0;
}
