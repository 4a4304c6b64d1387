#include "rubble/runtime/Structure.hpp"

#include <cmath>
#include <map>
#include <string>

#include "core/Rotation.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "runtime/MaterialByName.hpp"
#include "runtime/StructureMonitor.hpp"

namespace rubble {

struct Structure::Impl {
    explicit Impl(const StructurePolicy& p) : policy(p), monitor(policy) {}
    struct Body {
        const Material* material = nullptr;
        double volume = 0;
        Vec3 centroid;
    };
    StructurePolicy policy;
    detail::StructureMonitor monitor; // reads `policy` at every call
    std::map<BodyId, Body> bodies;
    std::uint64_t steps = 0;
};

Structure::Structure(const StructurePolicy& policy) : impl_(std::make_unique<Impl>(policy)) {}
Structure::~Structure() = default;
Structure::Structure(Structure&&) noexcept = default;
Structure& Structure::operator=(Structure&&) noexcept = default;

Status Structure::add(BodyId id, const std::vector<ConvexPolytope>& worldParts, std::string_view material,
                      bool root) {
    if (id == 0)
        return Error{ErrorCode::InvalidInput, "Structure::add: body id 0 is reserved"};
    const Result<const Material*> named = detail::materialByName(material);
    if (!named)
        return Error{ErrorCode::InvalidInput, "Structure::add: " + named.error().message};
    const Material* m = named.value();
    if (worldParts.empty())
        return Error{ErrorCode::InvalidInput, "Structure::add: body " + std::to_string(id) + " has no parts"};
    Impl::Body body{m, 0, {}};
    for (std::size_t i = 0; i < worldParts.size(); ++i) {
        const double v = worldParts[i].volume();
        if (!(v > 0) || !std::isfinite(v))
            return Error{ErrorCode::InvalidInput, "Structure::add: part " + std::to_string(i) + " of body " +
                                                      std::to_string(id) + " has no volume"};
        body.volume += v;
        body.centroid = body.centroid + worldParts[i].centroid() * v;
    }
    body.centroid = body.centroid * (1 / body.volume);
    impl_->monitor.add(id, worldParts, *m, root, id);
    impl_->bodies[id] = body;
    return Status::ok();
}

Status Structure::add(BodyId id, const Mesh& mesh, const Frame& placement, std::string_view material,
                      bool root) {
    if (!detail::isRotation(placement.rotation) || !isFinite(placement.translation))
        return Error{ErrorCode::InvalidInput, "Structure::add: the placement of body " + std::to_string(id) +
                                                  " is not a rigid motion"};
    Result<Decomposition> parts = decompose(mesh);
    if (!parts)
        return parts.error();
    std::vector<ConvexPolytope> world;
    world.reserve(parts->parts.size());
    for (const ConvexPolytope& part : parts->parts)
        world.push_back(part.transformed(placement));
    return add(id, world, material, root);
}

bool Structure::remove(BodyId id) {
    if (!impl_->bodies.erase(id))
        return false;
    impl_->monitor.remove(id);
    return true;
}

bool Structure::contains(BodyId id) const {
    return impl_->bodies.count(id) > 0;
}

std::size_t Structure::size() const {
    return impl_->bodies.size();
}

void Structure::addLoad(BodyId id, const Vec3& force, const Vec3& point) {
    impl_->monitor.addLoad(id, force, point);
}

void Structure::damage(const Vec3& point, double impulse) {
    impl_->monitor.damage(point, impulse);
}

StructureStep Structure::step(const Vec3& gravity) {
    Impl& im = *impl_;
    ++im.steps;
    StructureStep out;
    int broken = 0;
    const std::vector<BodyId> fallen = im.monitor.step(gravity, broken);
    out.residual = im.monitor.residual();
    out.breaks = im.monitor.breaks();
    for (StructureBreak& e : out.breaks)
        e.frame = im.steps;
    for (BodyId id : fallen) {
        const auto it = im.bodies.find(id);
        if (it == im.bodies.end())
            continue;
        const Impl::Body& b = it->second;
        StructureCollapse c;
        c.frame = im.steps;
        c.body = id;
        c.position = b.centroid;
        c.volume = b.volume;
        c.mass = b.material->density * b.volume;
        c.byStress = true;
        c.material = b.material->name;
        out.collapses.push_back(std::move(c));
        im.monitor.remove(id);
        im.bodies.erase(it);
    }
    return out;
}

std::vector<StructureBond> Structure::bonds() const {
    return impl_->monitor.bonds();
}

} // namespace rubble
