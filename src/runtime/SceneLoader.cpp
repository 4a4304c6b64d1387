#include "rubble/SceneLoader.hpp"

#include <cmath>

#include "rubble/MassProperties.hpp"
#include "rubble/MeshIO.hpp"

namespace rubble {
namespace {

std::string where(const SceneConfig& scene, const SceneObject& o) {
    (void)scene;
    return "line " + std::to_string(o.line);
}

// The model's mesh scaled, or a stand-in box with a warning.
Mesh modelOrStandIn(const SceneConfig& scene, const SceneObject& o, std::vector<std::string>& warnings) {
    if (!o.model.empty() && o.modelFound) {
        Result<Mesh> mesh = readMesh(o.modelPath);
        if (mesh && !mesh->empty())
            return mesh->transformed(Mat3::identity(), o.scale, Vec3{});
        warnings.push_back(where(scene, o) + ": model '" + o.model + "' unreadable (" +
                           (mesh ? std::string("no triangles") : mesh.error().message) +
                           "); using a stand-in box");
    } else {
        warnings.push_back(where(scene, o) + ": model '" + o.model + "' not found; using a stand-in box");
    }
    const Vec3 h = o.scale * 0.5;
    return makeBox(-h, h);
}

} // namespace

LoadedScene loadScene(const SceneConfig& scene, DestructionRuntime& runtime,
                      const SceneLoadOptions& options) {
    LoadedScene out;
    for (const SceneWarning& w : scene.warnings)
        out.warnings.push_back(w.message);
    // ground: the thesis's 1×1×1 cube scaled by (sx, sy, sz)
    if (scene.ground.line != 0) {
        const Vec3 h{std::abs(scene.ground.scale.x) * 0.5, std::abs(scene.ground.scale.y) * 0.5,
                     std::abs(scene.ground.scale.z) * 0.5};
        out.ground = runtime.addGround(scene.ground.position, h);
        out.groundTop = scene.ground.position.y + h.y;
    }
    if (options.loadVehicle && scene.vehicle.line != 0) {
        std::vector<std::string> vehicleWarnings;
        const Mesh mesh = modelOrStandIn(scene, scene.vehicle, vehicleWarnings);
        for (std::string& w : vehicleWarnings)
            out.warnings.push_back(std::move(w));
        Result<BodyId> body = runtime.addConvexBody(
            mesh.positions, Frame{Mat3::identity(), scene.vehicle.position}, scene.vehicle.mass, true);
        if (body)
            out.vehicle = *body;
        else
            out.warnings.push_back(where(scene, scene.vehicle) + ": vehicle skipped (" +
                                   body.error().message + ")");
    }
    for (std::size_t index = 0; index < scene.objects.size(); ++index) {
        const SceneObject& o = scene.objects[index];
        Mesh mesh = modelOrStandIn(scene, o, out.warnings);
        if (options.prepareMesh)
            options.prepareMesh(mesh);
        const double volume = std::abs(signedVolume(mesh));
        ObjectDesc desc;
        desc.density = o.isStatic() || volume <= 0 ? options.staticDensity : o.mass / volume;
        desc.impulseThreshold = options.impulseThreshold;
        desc.fracture = options.fracture;
        desc.mesh = std::move(mesh);
        Result<ObjectId> id =
            runtime.addObject(std::move(desc), Frame{Mat3::identity(), o.position}, o.isStatic());
        if (!id) {
            out.warnings.push_back(where(scene, o) + ": '" + o.model + "' rejected (" + id.error().message +
                                   "); using an indestructible stand-in box");
            const Vec3 h = o.scale * 0.5;
            ObjectDesc box;
            box.mesh = makeBox(-h, h);
            if (options.prepareMesh)
                options.prepareMesh(box.mesh);
            box.destructible = false;
            box.density = o.isStatic() ? options.staticDensity : o.mass / std::max(1e-9, 8 * h.x * h.y * h.z);
            id = runtime.addObject(std::move(box), Frame{Mat3::identity(), o.position}, o.isStatic());
            if (!id)
                continue;
        }
        if (const ObjectState* st = runtime.world().object(*id); st && !st->warning.empty())
            out.warnings.push_back(where(scene, o) + ": '" + o.model + "': " + st->warning);
        if (const BodyRecord* b = runtime.bodyOf(*id))
            out.initialVolume += b->volume;
        out.objects.push_back(*id);
        out.sceneIndex.push_back(index);
    }
    return out;
}

} // namespace rubble
