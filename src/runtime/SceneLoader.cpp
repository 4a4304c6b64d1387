#include "rubble/runtime/SceneLoader.hpp"

#include <algorithm>
#include <cmath>

#include "rubble/fracture/Roughness.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/io/DecompositionFile.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/structure/Material.hpp"

#include "geometry/FormerMeshHash.hpp"

namespace rubble {
namespace {

std::string where(const SceneConfig& scene, const SceneObject& o) {
    (void)scene;
    return "line " + std::to_string(o.line);
}

// A polytope scaled per axis by s (all positive).
ConvexPolytope scaledPolytope(const ConvexPolytope& p, const Vec3& s) {
    std::vector<PolytopeFace> faces = p.faceList();
    for (PolytopeFace& f : faces) {
        for (Vec3& c : f.corners)
            c = {c.x * s.x, c.y * s.y, c.z * s.z};
        const Vec3 n = f.plane.normal;
        f.plane.normal = normalized(Vec3{n.x / s.x, n.y / s.y, n.z / s.z});
        f.plane.offset = dot(f.plane.normal, f.corners.front());
    }
    return ConvexPolytope::fromFaces(std::move(faces));
}

// A model's mesh and, when MODEL.parts.json beside it was made for this mesh, its cached convex parts.
struct Model {
    Mesh mesh;
    std::vector<ConvexPolytope> parts;
};

// The model's mesh scaled (with its cached parts), or a stand-in box with a warning.
Model modelOrStandIn(const SceneConfig& scene, const SceneObject& o, std::vector<std::string>& warnings) {
    if (!o.model.empty() && o.modelFound) {
        Result<Mesh> mesh = readMesh(o.modelPath);
        if (mesh && !mesh->empty()) {
            Model m;
            const std::filesystem::path cached = decompositionPathFor(o.modelPath);
            std::error_code ec;
            const bool positive = o.scale.x > 0 && o.scale.y > 0 && o.scale.z > 0;
            if (positive && std::filesystem::exists(cached, ec)) {
                auto file = readDecompositionFile(cached);
                if (!file)
                    warnings.push_back(where(scene, o) + ": " + file.error().message +
                                       "; decomposing at load");
                else if (file->meshHash != mesh->hash() && file->meshHash != detail::formerMeshHash(*mesh))
                    warnings.push_back(where(scene, o) + ": " + cached.string() +
                                       " was made for another mesh; decomposing at load");
                else
                    for (const ConvexPolytope& p : file->parts)
                        m.parts.push_back(scaledPolytope(p, o.scale));
            }
            m.mesh = mesh->transformed(Mat3::identity(), o.scale, Vec3{});
            return m;
        }
        warnings.push_back(where(scene, o) + ": model '" + o.model + "' unreadable (" +
                           (mesh ? std::string("no triangles") : mesh.error().message) +
                           "); using a stand-in box");
    } else {
        warnings.push_back(where(scene, o) + ": model '" + o.model + "' not found; using a stand-in box");
    }
    const Vec3 h = o.scale * 0.5;
    return {makeBox(-h, h), {}};
}

// Volume of the intersection of two boxes (0 when they do not overlap).
double overlapVolume(const Aabb& a, const Aabb& b) {
    double v = 1;
    for (int k = 0; k < 3; ++k)
        v *= std::max(0.0, std::min(a.hi[k], b.hi[k]) - std::max(a.lo[k], b.lo[k]));
    return v;
}

double boxVolume(const Aabb& a) {
    const Vec3 s = a.size();
    return s.x * s.y * s.z;
}

// The roughness of o's cuts: its roughness field over its material's preset, else the options'.
Roughness objectRoughness(const SceneObject& o, const SceneLoadOptions& options) {
    const Roughness& base = options.fracture.roughness;
    if (!o.roughness && !options.materialRoughness)
        return base;
    const std::string material = o.material.empty() ? defaultMaterial().name : o.material;
    Result<Roughness> chosen = chooseRoughness({material, o.roughness, {}, {}});
    if (!chosen) // the parser checked the field and the material
        return base;
    chosen->seed = base.seed;
    chosen->maxTrianglesPerPiece = base.maxTrianglesPerPiece;
    return *chosen;
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
        const Mesh mesh = modelOrStandIn(scene, scene.vehicle, vehicleWarnings).mesh;
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
    struct Placed {
        Aabb bounds;
        bool isStatic = true;
        std::size_t line = 0;
    };
    std::vector<Placed> placed;
    for (std::size_t index = 0; index < scene.objects.size(); ++index) {
        const SceneObject& o = scene.objects[index];
        Model model = modelOrStandIn(scene, o, out.warnings);
        Mesh& mesh = model.mesh;
        if (options.prepareMesh)
            options.prepareMesh(mesh);
        // Bodies placed inside each other would push apart in one physics step of unbounded cost (600
        // buildings on one spot: 6.6 s and 1.4 GB for the first step), so a moving object whose bounds lie
        // mostly inside an earlier object's (or a static one inside a moving one's) is not loaded.
        const Aabb bounds{mesh.bounds().lo + o.position, mesh.bounds().hi + o.position};
        const auto clash = std::find_if(placed.begin(), placed.end(), [&](const Placed& p) {
            return (!o.isStatic() || !p.isStatic) &&
                   overlapVolume(bounds, p.bounds) >
                       options.maxOverlap * std::min(boxVolume(bounds), boxVolume(p.bounds));
        });
        if (clash != placed.end()) {
            out.warnings.push_back(where(scene, o) + ": '" + o.model + "' lies inside the object of line " +
                                   std::to_string(clash->line) +
                                   " (a moving body there would blow the pile apart); not loaded");
            continue;
        }
        placed.push_back({bounds, o.isStatic(), o.line});
        const double volume = std::abs(signedVolume(mesh));
        ObjectDesc desc;
        desc.density = o.isStatic() || volume <= 0 ? options.staticDensity : o.mass / volume;
        desc.impulseThreshold = options.impulseThreshold;
        desc.material = o.material;
        desc.fracture = options.fracture;
        desc.fracture.roughness = objectRoughness(o, options);
        desc.mesh = std::move(mesh);
        desc.convexParts = std::move(model.parts);
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
            box.material = o.material;
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
