#include "NetView.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <vector>

#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/runtime/SceneLoader.hpp"

namespace demo {

namespace {

/// Column-major model matrix of a rigid frame.
M4 toM4(const rubble::Frame& f) {
    M4 m;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            m.m[c * 4 + r] = static_cast<float>(f.rotation.m[r][c]);
    m.m[12] = static_cast<float>(f.translation.x);
    m.m[13] = static_cast<float>(f.translation.y);
    m.m[14] = static_cast<float>(f.translation.z);
    return m;
}

} // namespace

NetView::NetView() = default;
NetView::~NetView() = default;

bool NetView::connect(const std::string& address, std::uint16_t port, int workers,
                      const rubble::SceneConfig& scene, std::string& error) {
    rubble::DestructionWorld::Config config; // the snapshot brings the host's settings
    config.deterministic = true;
    config.workers = workers;
    world_ = std::make_unique<rubble::DestructionWorld>(config);
    {
        rubble::bullet::PhysicsWorld physics;
        rubble::bullet::BulletBinding binding(physics);
        rubble::DestructionRuntime::Config rc;
        rc.world = config;
        rubble::DestructionRuntime loader(binding, rc);
        rubble::SceneLoadOptions lo;
        lo.loadVehicle = false; // as rubble-server loads it
        (void)rubble::loadScene(scene, loader, lo);
        if (rubble::Status st = rubble::restoreSnapshot(*world_, rubble::takeSnapshot(loader.world())); !st) {
            error = st.message();
            return false;
        }
    }
    auto client = rubble::net::NetClient::connect(*world_, config, address, port);
    if (!client) {
        error = client.error().message;
        return false;
    }
    client_ = std::move(*client);
    client_->setOnOutcome([this](const rubble::FractureOutcome& o) {
        for (const rubble::AdoptedPiece& p : o.pieces)
            fresh_[p.id] = 1.0f;
    });
    return true;
}

rubble::Status NetView::service(int timeoutMs) {
    if (!client_)
        return rubble::Error{rubble::ErrorCode::IoError, "not connected"};
    return client_->service(timeoutMs);
}

void NetView::draw(Renderer& renderer, int texture, float dt) {
    drawn_ = 0;
    if (!client_ || !client_->stats().joined)
        return;
    const double frame = static_cast<double>(client_->stats().frame) - kViewLag;
    std::map<rubble::ObjectId, Visual> kept;
    V3 lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
          std::numeric_limits<float>::max()};
    V3 hi = -lo;
    for (rubble::ObjectId id : world_->objects()) {
        const rubble::ObjectState* o = world_->object(id);
        const std::optional<rubble::Frame> at = client_->placement(id, frame);
        if (!o || !at)
            continue;
        Visual v;
        if (auto it = visuals_.find(id); it != visuals_.end()) {
            v = it->second;
            visuals_.erase(it);
        }
        if (v.mesh < 0 || v.version != o->version) {
            if (v.mesh >= 0)
                renderer.removeMesh(v.mesh);
            v.mesh = renderer.addMesh(o->mesh, texture);
            v.version = o->version;
        }
        if (auto f = fresh_.find(id); f != fresh_.end())
            v.heat = f->second;
        v.heat = std::max(0.0f, v.heat - dt * 0.6f);
        renderer.drawMesh(v.mesh, toM4(*at), v.heat);
        ++drawn_;
        if (!framed_) {
            const rubble::Aabb box = o->mesh.bounds();
            for (int corner = 0; corner < 8; ++corner) {
                const rubble::Vec3 p =
                    at->apply({corner & 1 ? box.hi.x : box.lo.x, corner & 2 ? box.hi.y : box.lo.y,
                               corner & 4 ? box.hi.z : box.lo.z});
                lo = {std::min(lo.x, static_cast<float>(p.x)), std::min(lo.y, static_cast<float>(p.y)),
                      std::min(lo.z, static_cast<float>(p.z))};
                hi = {std::max(hi.x, static_cast<float>(p.x)), std::max(hi.y, static_cast<float>(p.y)),
                      std::max(hi.z, static_cast<float>(p.z))};
            }
        }
        kept[id] = v;
    }
    fresh_.clear();
    for (const auto& [id, v] : visuals_) // objects that are gone (fractured, removed)
        renderer.removeMesh(v.mesh);
    visuals_ = std::move(kept);
    if (!framed_ && drawn_ > 0) {
        framed_ = true;
        centre_ = (lo + hi) * 0.5f;
        radius_ = std::max(5.0f, 0.5f * len(hi - lo));
    }
}

bool NetView::shoot(const V3& eye, int index) {
    if (!client_ || !client_->stats().joined)
        return false;
    const double frame = static_cast<double>(client_->stats().frame) - kViewLag;
    std::vector<rubble::Vec3> targets;
    for (rubble::ObjectId id : world_->objects()) {
        const rubble::ObjectState* o = world_->object(id);
        if (const std::optional<rubble::Frame> at = client_->placement(id, frame); o->destructible && at)
            targets.push_back(at->apply(o->mesh.bounds().center()));
    }
    if (targets.empty())
        return false;
    const rubble::Vec3 from{eye.x, eye.y, eye.z};
    const rubble::Vec3 to = targets[static_cast<std::size_t>(index) % targets.size()];
    return static_cast<bool>(client_->shoot(from, rubble::normalized(to - from) * 120.0));
}

rubble::Status NetView::writeReplay(const std::string& folder) const {
    if (!client_)
        return rubble::Error{rubble::ErrorCode::InvalidInput, "not connected"};
    const std::filesystem::path dir = folder;
    return client_->writeReplay(dir / "game.rbsn", dir / "game.rbj");
}

void NetView::clear(Renderer& renderer) {
    for (const auto& [id, v] : visuals_)
        renderer.removeMesh(v.mesh);
    visuals_.clear();
}

void NetView::bounds(V3& centre, float& radius) const {
    centre = centre_;
    radius = framed_ ? radius_ : 0;
}

const rubble::net::ClientStats& NetView::stats() const {
    static const rubble::net::ClientStats none;
    return client_ ? client_->stats() : none;
}

std::uint64_t NetView::geometryHash() const {
    return world_ ? world_->geometryHash() : 0;
}

} // namespace demo
