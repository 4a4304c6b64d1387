// The C API's structure (rubble_structure_*) over rubble::Structure.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "capi/CApiSupport.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/rubble.h"
#include "rubble/runtime/Structure.hpp"

struct rubble_structure {
    static constexpr std::uint32_t kTag = 0x53545255; // "STRU"
    std::uint32_t tag = kTag;
    rubble::Structure structure;
    rubble::StructureStep last; // of the latest step
};

using namespace rubble::capi;

rubble_status rubble_structure_config_init(rubble_structure_config* config) {
    return guarded(__func__, [&](const char* fn) {
        if (!config)
            return invalid(fn, "config is null");
        const rubble::StructurePolicy defaults;
        config->bearing_friction = defaults.bearingFriction;
        config->converged = 1;
        config->damage_radius = defaults.damageRadius;
        config->damage_per_impulse = defaults.damagePerImpulse;
        return ok();
    });
}

rubble_status rubble_structure_create(const rubble_structure_config* config, rubble_structure** out) {
    return guarded(__func__, [&](const char* fn) {
        if (!out)
            return invalid(fn, "out is null");
        *out = nullptr;
        rubble_structure_config c;
        if (config)
            c = *config;
        else
            (void)rubble_structure_config_init(&c);
        for (const auto& [name, value] :
             {std::pair{"bearing_friction", c.bearing_friction}, std::pair{"damage_radius", c.damage_radius},
              std::pair{"damage_per_impulse", c.damage_per_impulse}})
            if (!(value >= 0) || !std::isfinite(value))
                return invalid(fn, (std::string(name) + " must be finite and >= 0").c_str());
        rubble::StructurePolicy p;
        p.bearingFriction = c.bearing_friction;
        p.damageRadius = c.damage_radius;
        p.damagePerImpulse = c.damage_per_impulse;
        p.stress.method = c.converged ? rubble::StressMethod::Auto : rubble::StressMethod::SweepBudget;
        *out = new rubble_structure{rubble_structure::kTag, rubble::Structure(p), {}};
        return ok();
    });
}

rubble_status rubble_structure_destroy(rubble_structure* structure) {
    return guarded(__func__,
                   [&](const char* fn) { return destroy(fn, structure, "not a structure handle"); });
}

rubble_status rubble_structure_add(rubble_structure* structure, uint32_t id, const rubble_mesh* mesh,
                                   const double rotation[9], const double translation[3],
                                   const char* material, int root) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure) || !valid(mesh) || !translation)
            return invalid(fn, "structure, mesh or translation is null or invalid");
        rubble::Frame place{rubble::Mat3::identity(), vec(translation)};
        if (rotation)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    place.rotation.m[r][c] = rotation[3 * r + c];
        const char* name = material ? material : "";
        if (rubble::Status s = structure->structure.add(id, mesh->mesh, place, name, root != 0); !s)
            return fail(s.error());
        return ok();
    });
}

rubble_status rubble_structure_remove(rubble_structure* structure, uint32_t id) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure))
            return invalid(fn, "structure is null or invalid");
        if (!structure->structure.remove(id))
            return invalid(fn, "no body with this id");
        return ok();
    });
}

rubble_status rubble_structure_add_load(rubble_structure* structure, uint32_t id, const double force[3],
                                        const double point[3]) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure) || !force || !point)
            return invalid(fn, "structure, force or point is null or invalid");
        if (!structure->structure.contains(id))
            return invalid(fn, "no body with this id");
        for (rubble::Status s :
             {rubble::checkParam("force", vec(force)), rubble::checkParam("point", vec(point))})
            if (!s)
                return invalid(fn, s.message().c_str());
        structure->structure.addLoad(id, vec(force), vec(point));
        return ok();
    });
}

rubble_status rubble_structure_damage(rubble_structure* structure, const double point[3], double impulse) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure) || !point)
            return invalid(fn, "structure or point is null or invalid");
        for (rubble::Status s :
             {rubble::checkParam("point", vec(point)), rubble::checkParam("impulse", impulse)})
            if (!s)
                return invalid(fn, s.message().c_str());
        structure->structure.damage(vec(point), impulse);
        return ok();
    });
}

rubble_status rubble_structure_step(rubble_structure* structure, const double gravity[3],
                                    rubble_structure_step_info* info) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure))
            return invalid(fn, "structure is null or invalid");
        const rubble::Vec3 g = gravity ? vec(gravity) : rubble::Vec3{0, -9.81, 0};
        if (!rubble::isFinite(g))
            return invalid(fn, "gravity is not finite");
        structure->last = structure->structure.step(g);
        if (info)
            *info = {structure->last.breaks.size(), structure->last.collapses.size(),
                     structure->last.residual};
        return ok();
    });
}

rubble_status rubble_structure_get_break(const rubble_structure* structure, size_t index,
                                         rubble_structure_break* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure) || !out)
            return invalid(fn, "structure or out is null or invalid");
        if (index >= structure->last.breaks.size())
            return invalid(fn, "index out of range");
        const rubble::StructureBreak& k = structure->last.breaks[index];
        out->step = k.frame;
        out->a = k.a;
        out->b = k.b;
        copy(k.position, out->position);
        copy(k.normal, out->normal);
        out->area = k.area;
        copy(k.force, out->force);
        out->utilisation = k.utilisation;
        out->damaged = k.damaged ? 1 : 0;
        out->material_a = k.materialA.c_str();
        out->material_b = k.materialB.c_str();
        return ok();
    });
}

rubble_status rubble_structure_get_collapse(const rubble_structure* structure, size_t index,
                                            rubble_structure_collapse* out) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure) || !out)
            return invalid(fn, "structure or out is null or invalid");
        if (index >= structure->last.collapses.size())
            return invalid(fn, "index out of range");
        const rubble::StructureCollapse& c = structure->last.collapses[index];
        out->step = c.frame;
        out->body = c.body;
        copy(c.position, out->position);
        out->volume = c.volume;
        out->mass = c.mass;
        out->material = c.material.c_str();
        return ok();
    });
}

rubble_status rubble_structure_count(const rubble_structure* structure, size_t* bodies, size_t* bonds) {
    return guarded(__func__, [&](const char* fn) {
        if (!valid(structure))
            return invalid(fn, "structure is null or invalid");
        if (bodies)
            *bodies = structure->structure.size();
        if (bonds)
            *bonds = structure->structure.bonds().size();
        return ok();
    });
}
