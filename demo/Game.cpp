#include "Game.hpp"

#include <BulletCollision/CollisionShapes/btShapeHull.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>

#include "rubble/ConvexDecomposition.hpp"
#include "rubble/DestructionWorld.hpp"
#include "rubble/MassProperties.hpp"
#include "rubble/MeshIO.hpp"

namespace demo {

namespace {

enum Group : int { kStatic = 1, kVehicle = 2, kProjectile = 4, kDebris = 8, kAll = 0xFFFF };

V3 toV3(const btVector3& v) {
    return {v.x(), v.y(), v.z()};
}
btVector3 toBt(const rubble::Vec3& v) {
    return {static_cast<btScalar>(v.x), static_cast<btScalar>(v.y), static_cast<btScalar>(v.z)};
}

/// Box-projected UVs (metres per repeat) for meshes that have none.
void ensureUvs(rubble::Mesh& m, double metresPerRepeat) {
    bool any = false;
    for (const auto& uv : m.uvs)
        if (uv.x != 0 || uv.y != 0) {
            any = true;
            break;
        }
    if (any)
        return;
    m.uvs.assign(m.triangles.size() * 3, {});
    for (size_t t = 0; t < m.triangles.size(); ++t) {
        const rubble::Vec3 n = m.triangleNormal(t);
        const double ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
        for (int c = 0; c < 3; ++c) {
            const rubble::Vec3& p = m.positions[m.triangles[t][static_cast<size_t>(c)]];
            rubble::Vec2 uv;
            if (ax >= ay && ax >= az)
                uv = {p.z, p.y};
            else if (ay >= az)
                uv = {p.x, p.z};
            else
                uv = {p.x, p.y};
            m.uvs[3 * t + static_cast<size_t>(c)] = {uv.x / metresPerRepeat, uv.y / metresPerRepeat};
        }
    }
}

/// A closed triangular prism: triangle (a, b, c) extruded by e, outward oriented.
rubble::Mesh prism(const rubble::Vec3& a, const rubble::Vec3& b, const rubble::Vec3& c,
                   const rubble::Vec3& e) {
    rubble::Mesh m;
    m.positions = {a - e * 0.5, b - e * 0.5, c - e * 0.5, a + e * 0.5, b + e * 0.5, c + e * 0.5};
    m.triangles = {{0, 2, 1}, {3, 4, 5}, {0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}, {2, 0, 3}, {2, 3, 5}};
    if (rubble::signedVolume(m) < 0)
        for (auto& t : m.triangles)
            std::swap(t[1], t[2]);
    return m;
}

rubble::Mesh standInJet() {
    rubble::Mesh jet = rubble::makeSphere({0, 0, 0}, 1.0, 16, 10);
    jet = jet.transformed(rubble::Mat3::identity(), {0.75, 0.62, 3.6}, {0, 0, 0});
    rubble::Mesh canopy = rubble::makeSphere({0, 0, 0}, 1.0, 12, 8);
    jet.append(canopy.transformed(rubble::Mat3::identity(), {0.42, 0.38, 1.2}, {0, 0.48, -1.0}));
    const rubble::Vec3 up{0, 0.16, 0};
    jet.append(prism({0.4, -0.1, -1.4}, {4.6, -0.1, 1.7}, {0.4, -0.1, 2.0}, up));
    jet.append(prism({-0.4, -0.1, -1.4}, {-4.6, -0.1, 1.7}, {-0.4, -0.1, 2.0}, up));
    jet.append(prism({0.3, 0.0, 2.2}, {1.9, 0.0, 3.6}, {0.3, 0.0, 3.6}, up * 0.7));
    jet.append(prism({-0.3, 0.0, 2.2}, {-1.9, 0.0, 3.6}, {-0.3, 0.0, 3.6}, up * 0.7));
    jet.append(prism({0, 0.3, 1.6}, {0, 2.1, 3.5}, {0, 0.3, 3.5}, {0.12, 0, 0}));
    jet.normals.clear();
    return jet;
}

class DebugLines : public btIDebugDraw {
public:
    explicit DebugLines(Renderer& r) : r_(r) {}
    void drawLine(const btVector3& a, const btVector3& b, const btVector3& c) override {
        r_.addLine(toV3(a), toV3(b), c.x(), c.y(), c.z());
    }
    void drawContactPoint(const btVector3& p, const btVector3& n, btScalar, int,
                          const btVector3& c) override {
        drawLine(p, p + n * 1.0f, c);
    }
    void reportErrorWarning(const char*) override {}
    void draw3dText(const btVector3&, const char*) override {}
    void setDebugMode(int m) override { mode_ = m; }
    int getDebugMode() const override { return mode_; }

private:
    Renderer& r_;
    int mode_ = 0;
};

} // namespace

struct Game::Body {
    enum class Kind { Ground, Vehicle, Object, Piece, Projectile };
    Kind kind = Kind::Object;
    std::unique_ptr<btRigidBody> rb;
    std::unique_ptr<btCollisionShape> shape;
    std::vector<std::unique_ptr<btCollisionShape>> children;
    int mesh = -1;
    int texture = 0;
    V3 tint{1, 1, 1};
    std::uint32_t object = 0;
    float heat = 0;
    float age = 0;
    float volume = 0;
    double density = 1;
    rubble::Mesh localMesh; // used by the stand-in fracture
    bool dead = false;
};

Game::Game() = default;

Game::~Game() {
    if (world_)
        for (auto& b : bodies_)
            world_->removeRigidBody(b->rb.get());
}

bool Game::fractureAvailable() {
#if RUBBLE_DEMO_HAS_RUNTIME
    return true;
#else
    return false;
#endif
}

Game::Body* Game::addBody(std::unique_ptr<Body> b) {
    b->rb->setUserPointer(b.get());
    int group = kStatic, mask = kAll;
    switch (b->kind) {
    case Body::Kind::Vehicle:
        group = kVehicle;
        mask = kAll & ~kProjectile;
        break;
    case Body::Kind::Projectile:
        group = kProjectile;
        mask = kAll & ~kVehicle & ~kProjectile;
        break;
    case Body::Kind::Piece:
        group = kDebris;
        break;
    default:
        break;
    }
    world_->addRigidBody(b->rb.get(), group, mask);
    bodies_.push_back(std::move(b));
    return bodies_.back().get();
}

void Game::removeBody(Body* b, Renderer& renderer) {
    world_->removeRigidBody(b->rb.get());
    if (b->mesh >= 0 && b->kind != Body::Kind::Projectile)
        renderer.removeMesh(b->mesh);
    auto it = std::find_if(bodies_.begin(), bodies_.end(), [b](const auto& p) { return p.get() == b; });
    if (it != bodies_.end())
        bodies_.erase(it);
}

void Game::clear(Renderer& renderer) {
    if (world_)
        for (auto& b : bodies_) {
            world_->removeRigidBody(b->rb.get());
            if (b->mesh >= 0)
                renderer.removeMesh(b->mesh);
        }
    bodies_.clear();
    vehicle_ = nullptr;
    world_.reset();
    solver_.reset();
    broadphase_.reset();
    dispatcher_.reset();
    collisionConfig_.reset();
#if RUBBLE_DEMO_HAS_RUNTIME
    destruction_.reset();
#endif
    particles_.clear();
    marks_.clear();
    counters_ = {};
    latencies_.clear();
    latencyCursor_ = timingCursor_ = 0;
}

bool Game::load(const rubble::SceneConfig& scene, Renderer& renderer, const GameSettings& settings,
                std::vector<std::string>& warnings, std::string& error) {
    clear(renderer);
    settings_ = settings;
    renderer.shadows = settings.shadows;
    collisionConfig_ = std::make_unique<btDefaultCollisionConfiguration>();
    dispatcher_ = std::make_unique<btCollisionDispatcher>(collisionConfig_.get());
    broadphase_ = std::make_unique<btDbvtBroadphase>();
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(),
                                                       collisionConfig_.get());
    world_->setGravity({0, -9.81f, 0});
#if RUBBLE_DEMO_HAS_RUNTIME
    rubble::DestructionWorld::Config cfg;
    cfg.workers = settings.workers;
    cfg.deterministic = settings.deterministic;
    cfg.seed = 20260522;
    destruction_ = std::make_shared<rubble::DestructionWorld>(cfg);
#endif
    for (const auto& w : scene.warnings)
        warnings.push_back(w.message);

    // Ground: a solid unit cube scaled (thesis: "generated as a solid cube with 1x1x1 size").
    {
        const auto& g = scene.ground;
        const V3 half{static_cast<float>(g.scale.x * 0.5), static_cast<float>(g.scale.y * 0.5),
                      static_cast<float>(g.scale.z * 0.5)};
        rubble::Mesh box = rubble::makeBox({-half.x, -half.y, -half.z}, {half.x, half.y, half.z});
        box.uvs.clear();
        box.uvs.resize(box.triangles.size() * 3);
        for (size_t t = 0; t < box.triangles.size(); ++t)
            for (int c = 0; c < 3; ++c) {
                const auto& p = box.positions[box.triangles[t][static_cast<size_t>(c)]];
                box.uvs[3 * t + static_cast<size_t>(c)] = {(p.x + g.position.x) / 16.0,
                                                           (p.z + g.position.z) / 16.0};
            }
        auto b = std::make_unique<Body>();
        b->kind = Body::Kind::Ground;
        b->shape = std::make_unique<btBoxShape>(btVector3(half.x, half.y, half.z));
        btTransform t;
        t.setIdentity();
        t.setOrigin(toBt(g.position));
        b->rb = std::make_unique<btRigidBody>(0.0f, nullptr, b->shape.get());
        b->rb->setWorldTransform(t);
        b->rb->setFriction(0.9f);
        b->texture = g.textureFound ? renderer.loadTexture(g.texturePath, "grid", warnings)
                                    : renderer.proceduralTexture("grid");
        b->mesh = renderer.addMesh(box, b->texture, 0.95f, 1.0f, 0.92f);
        groundTop_ = static_cast<float>(g.position.y + half.y);
        addBody(std::move(b));
    }

    // Vehicle.
    {
        const auto& v = scene.vehicle;
        rubble::Mesh mesh;
        bool standIn = true;
        if (v.modelFound) {
            auto r = rubble::readMesh(v.modelPath);
            if (r && !r->empty()) {
                mesh = r.value();
                mesh = mesh.transformed(rubble::Mat3::identity(), v.scale, {0, 0, 0});
                standIn = false;
            } else {
                warnings.push_back(scene.baseDir.string() + ":" + std::to_string(v.line) +
                                   ": vehicle model '" + v.model + "' unreadable (" +
                                   (r ? "empty" : r.error().message) + "); using the built-in jet");
            }
        }
        if (standIn)
            mesh = standInJet();
        ensureUvs(mesh, 2.0);
        const rubble::Aabb bb = mesh.bounds();
        mesh = mesh.translated(rubble::Vec3{} - bb.center());
        const rubble::Vec3 he = bb.size() * 0.5;
        noseOffset_ = static_cast<float>(std::max(he.z, std::max(he.x, he.y))) + 2.0f;
        auto b = std::make_unique<Body>();
        b->kind = Body::Kind::Vehicle;
        b->shape = std::make_unique<btBoxShape>(btVector3(static_cast<btScalar>(he.x * 0.6),
                                                          static_cast<btScalar>(he.y * 0.8),
                                                          static_cast<btScalar>(he.z * 0.9)));
        const float mass = std::max(static_cast<float>(v.mass), 1.0f);
        btVector3 inertia;
        b->shape->calculateLocalInertia(mass, inertia);
        btTransform t;
        t.setIdentity();
        t.setOrigin(toBt(v.position));
        b->rb = std::make_unique<btRigidBody>(
            btRigidBody::btRigidBodyConstructionInfo(mass, nullptr, b->shape.get(), inertia));
        b->rb->setWorldTransform(t);
        b->rb->setFlags(b->rb->getFlags() | BT_DISABLE_WORLD_GRAVITY);
        b->rb->setActivationState(DISABLE_DEACTIVATION);
        b->rb->setDamping(0.05f, 0.6f);
        b->texture = v.textureFound ? renderer.loadTexture(v.texturePath, "metal", warnings)
                                    : renderer.proceduralTexture("metal");
        vehicleTexture_ = b->texture;
        b->tint = {0.85f, 0.9f, 1.0f};
        b->mesh = renderer.addMesh(mesh, b->texture, 0.85f, 0.9f, 1.0f);
        speed_ = v.mass > 0 ? 30.0f : 0.0f;
        vehicle_ = addBody(std::move(b));
        vehicle_->rb->setLinearVelocity(btVector3(0, 0, -speed_));
    }

    // Objects.
    for (const auto& o : scene.objects) {
        rubble::Mesh mesh;
        bool ok = false;
        if (o.modelFound) {
            auto r = rubble::readMesh(o.modelPath);
            if (r && !r->empty()) {
                mesh = r.value();
                ok = true;
            } else {
                warnings.push_back(o.modelPath.string() + " (scene line " + std::to_string(o.line) +
                                   "): unreadable (" + (r ? "empty" : r.error().message) +
                                   "); using a box stand-in");
            }
        }
        if (!ok)
            mesh = rubble::makeBox({-1, -1, -1}, {1, 1, 1});
        mesh = mesh.transformed(rubble::Mat3::identity(), o.scale, {0, 0, 0});
        mesh.normals.clear();
        ensureUvs(mesh, 4.0);
        rubble::MassProperties mp = rubble::computeMassProperties(mesh);
        double volume = mp.volume;
        rubble::Vec3 com = mp.centerOfMass;
        if (!(volume > 1e-9)) {
            warnings.push_back(o.modelPath.string() + " (scene line " + std::to_string(o.line) +
                               "): mesh is not a closed outward solid (volume " + std::to_string(volume) +
                               "); centred on its bounding box");
            const rubble::Aabb bb = mesh.bounds();
            com = bb.center();
            const rubble::Vec3 s = bb.size();
            volume = std::max(1e-3, s.x * s.y * s.z);
        }
        mesh = mesh.translated(rubble::Vec3{} - com);
        const bool isStatic = o.mass <= 0;
        const double density = isStatic ? 400.0 : o.mass / volume;

        auto b = std::make_unique<Body>();
        b->kind = Body::Kind::Object;
        b->volume = static_cast<float>(volume);
        std::vector<std::vector<rubble::Vec3>> parts;
        rubble::Mesh renderMesh = mesh;
#if RUBBLE_DEMO_HAS_RUNTIME
        {
            rubble::ObjectDesc desc;
            desc.mesh = mesh;
            desc.density = density;
            desc.impulseThreshold = settings.impulseThreshold;
            desc.fracture = settings.fracture;
            auto id = destruction_->addObject(std::move(desc));
            if (id) {
                b->object = id.value();
                if (const rubble::ObjectState* st = destruction_->object(b->object)) {
                    if (!st->warning.empty())
                        warnings.push_back(o.modelPath.string() + " (scene line " + std::to_string(o.line) +
                                           "): " + st->warning);
                    renderMesh = st->mesh;
                    for (const auto& part : st->convexParts)
                        parts.push_back(part.vertices());
                }
            } else {
                warnings.push_back("scene line " + std::to_string(o.line) + ": " + id.error().message);
            }
        }
#endif
#if !RUBBLE_DEMO_HAS_RUNTIME
        // Concave objects (arches, walls, stepped towers) get a convex decomposition, cached by mesh hash.
        if (parts.empty()) {
            static rubble::DecompositionCache cache;
            auto dec = cache.get(renderMesh);
            if (dec && !dec->parts.empty())
                for (const auto& part : dec->parts)
                    parts.push_back(part.vertices());
        }
#endif
        if (parts.empty())
            parts.push_back(renderMesh.positions);
        b->density = density;
#if !RUBBLE_DEMO_HAS_RUNTIME
        b->object = nextLocalId_++;
        b->localMesh = renderMesh;
#endif
        auto compound = std::make_unique<btCompoundShape>();
        for (const auto& pts : parts) {
            auto hull = std::make_unique<btConvexHullShape>();
            for (const auto& p : pts)
                hull->addPoint(toBt(p), false);
            hull->recalcLocalAabb();
            hull->setMargin(0.02f);
            btTransform id;
            id.setIdentity();
            compound->addChildShape(id, hull.get());
            b->children.push_back(std::move(hull));
        }
        b->shape = std::move(compound);
        const float mass = isStatic ? 0.0f : static_cast<float>(o.mass);
        btVector3 inertia(0, 0, 0);
        if (mass > 0)
            inertia = btVector3(static_cast<btScalar>(std::max(1e-6, mp.inertia.m[0][0] * density)),
                                static_cast<btScalar>(std::max(1e-6, mp.inertia.m[1][1] * density)),
                                static_cast<btScalar>(std::max(1e-6, mp.inertia.m[2][2] * density)));
        btTransform t;
        t.setIdentity();
        t.setOrigin(toBt(o.position + com));
        b->rb = std::make_unique<btRigidBody>(
            btRigidBody::btRigidBodyConstructionInfo(mass, nullptr, b->shape.get(), inertia));
        b->rb->setWorldTransform(t);
        b->rb->setFriction(0.8f);
        b->rb->setDamping(0.02f, 0.1f);
        b->texture = o.textureFound ? renderer.loadTexture(o.texturePath, "concrete", warnings)
                                    : renderer.proceduralTexture("concrete");
        b->mesh = renderer.addMesh(renderMesh, b->texture);
        addBody(std::move(b));
    }
    counters_.warnings = static_cast<int>(warnings.size());
    V3 pos, fwd, up;
    vehicleFrame(pos, fwd, up);
    camera_.snap(pos, fwd, up);
    (void)error;
    return true;
}

void Game::vehicleFrame(V3& pos, V3& forward, V3& up) const {
    if (!vehicle_) {
        pos = {};
        forward = {0, 0, -1};
        up = {0, 1, 0};
        return;
    }
    const btTransform& t = vehicle_->rb->getWorldTransform();
    pos = toV3(t.getOrigin());
    forward = toV3(t.getBasis() * btVector3(0, 0, -1));
    up = toV3(t.getBasis() * btVector3(0, 1, 0));
}

void Game::controlVehicle(const ControlInput& in, float dt) {
    if (!vehicle_)
        return;
    btRigidBody* rb = vehicle_->rb.get();
    const btMatrix3x3& R = rb->getWorldTransform().getBasis();
    speed_ = std::clamp(speed_ + in.throttle * 25.0f * dt, 0.0f, 90.0f);
    const btVector3 right = R * btVector3(1, 0, 0);
    // Stabilising assist: without roll input the wings level themselves.
    const float level = -right.y() * 1.6f * (1.0f - std::min(1.0f, std::fabs(in.roll)));
    const btVector3 localRate(-in.pitch * 1.25f, in.yaw * 0.85f, in.roll * 2.0f + level);
    const btVector3 target = R * localRate;
    btVector3 w = rb->getAngularVelocity();
    // Angular velocity is driven to the commanded rate: a collision cannot leave the vehicle spinning.
    w += (target - w) * (1.0f - std::exp(-10.0f * dt));
    rb->setAngularVelocity(w);
    const btVector3 fwd = R * btVector3(0, 0, -1);
    btVector3 v = rb->getLinearVelocity();
    v += (fwd * speed_ - v) * (1.0f - std::exp(-2.5f * dt));
    rb->setLinearVelocity(v);
    rb->activate(true);
}

void Game::fire(Renderer& renderer) {
    (void)renderer;
    const btTransform& vt = vehicle_->rb->getWorldTransform();
    const btVector3 fwd = vt.getBasis() * btVector3(0, 0, -1);
    auto b = std::make_unique<Body>();
    b->kind = Body::Kind::Projectile;
    b->shape = std::make_unique<btSphereShape>(0.35f);
    const float m = settings_.projectileMass;
    btVector3 inertia;
    b->shape->calculateLocalInertia(m, inertia);
    btTransform t;
    t.setIdentity();
    t.setOrigin(vt.getOrigin() + fwd * noseOffset_);
    b->rb = std::make_unique<btRigidBody>(
        btRigidBody::btRigidBodyConstructionInfo(m, nullptr, b->shape.get(), inertia));
    b->rb->setWorldTransform(t);
    b->rb->setLinearVelocity(vehicle_->rb->getLinearVelocity() + fwd * settings_.projectileSpeed);
    b->rb->setCcdMotionThreshold(0.2f);
    b->rb->setCcdSweptSphereRadius(0.3f);
    b->rb->setGravity(btVector3(0, -2.0f, 0));
    b->rb->setFlags(b->rb->getFlags() | BT_DISABLE_WORLD_GRAVITY);
    addBody(std::move(b));
    bodies_.back()->rb->setGravity(btVector3(0, -2.0f, 0));
    ++counters_.shots;
}

void Game::processContacts(Renderer& renderer) {
    (void)renderer;
    const int n = dispatcher_->getNumManifolds();
    for (int i = 0; i < n; ++i) {
        btPersistentManifold* m = dispatcher_->getManifoldByIndexInternal(i);
        if (m->getNumContacts() == 0)
            continue;
        auto* a = static_cast<Body*>(m->getBody0()->getUserPointer());
        auto* b = static_cast<Body*>(m->getBody1()->getUserPointer());
        if (!a || !b)
            continue;
        const bool aProj = a->kind == Body::Kind::Projectile, bProj = b->kind == Body::Kind::Projectile;
        int best = 0;
        for (int c = 1; c < m->getNumContacts(); ++c)
            if (m->getContactPoint(c).getDistance() < m->getContactPoint(best).getDistance())
                best = c;
        const btManifoldPoint& cp = m->getContactPoint(best);
        if (aProj || bProj) {
            Body* proj = aProj ? a : b;
            Body* other = aProj ? b : a;
            if (proj->dead || other->kind == Body::Kind::Projectile)
                continue;
            const btVector3 pt = aProj ? cp.getPositionWorldOnB() : cp.getPositionWorldOnA();
            const btVector3 nrm = aProj ? cp.m_normalWorldOnB : -cp.m_normalWorldOnB;
            proj->dead = true;
            const btVector3 rel =
                proj->rb->getLinearVelocity() -
                other->rb->getVelocityInLocalPoint(pt - other->rb->getCenterOfMassPosition());
            const double impulse = static_cast<double>(settings_.projectileMass) * rel.length();
            if (other->kind == Body::Kind::Object || other->kind == Body::Kind::Piece) {
                ++counters_.impacts;
                marks_.push_back({toV3(pt), toV3(nrm), 0});
                if (marks_.size() > 64)
                    marks_.pop_front();
                particles_.impactBurst(toV3(pt), toV3(nrm), 1.0f, burstSeed_++);
#if RUBBLE_DEMO_HAS_RUNTIME
                if (other->object) {
                    const btTransform inv = other->rb->getWorldTransform().inverse();
                    const btVector3 lp = inv * pt;
                    const btVector3 ln = inv.getBasis() * nrm;
                    rubble::Impact imp;
                    imp.point = {lp.x(), lp.y(), lp.z()};
                    imp.normal = {ln.x(), ln.y(), ln.z()};
                    imp.impulse = impulse;
                    if (destruction_->submitImpact(other->object, imp))
                        ++counters_.submitted;
                }
#else
                if (other->object && impulse >= settings_.impulseThreshold && other->volume > 0.2f &&
                    !local_.busy(other->object)) {
                    const btTransform inv = other->rb->getWorldTransform().inverse();
                    const btVector3 lp = inv * pt;
                    const btVector3 ln = inv.getBasis() * nrm;
                    const auto& law = settings_.fracture.sizeLaw;
                    const double size = std::clamp(law.base + law.scale * std::pow(impulse, law.exponent),
                                                   law.minSize, law.maxSize);
                    local_.submit(other->object, other->localMesh, {lp.x(), lp.y(), lp.z()},
                                  {ln.x(), ln.y(), ln.z()}, size,
                                  1000003ull * counters_.frame + other->object, counters_.frame);
                    ++counters_.submitted;
                }
#endif
            } else if (other->kind == Body::Kind::Ground) {
                particles_.impactBurst(toV3(pt), toV3(nrm), 0.3f, burstSeed_++);
            }
            continue;
        }
#if RUBBLE_DEMO_HAS_RUNTIME
        // Heavy collisions (the vehicle ramming a building, a falling slab) fracture too.
        float maxImpulse = 0;
        for (int c = 0; c < m->getNumContacts(); ++c)
            maxImpulse = std::max(maxImpulse, m->getContactPoint(c).getAppliedImpulse());
        if (maxImpulse > settings_.collisionImpulse) {
            for (Body* target : {a, b}) {
                if (!target->object || target->dead)
                    continue;
                const btVector3 pt = target == a ? cp.getPositionWorldOnA() : cp.getPositionWorldOnB();
                const btVector3 nrm = target == a ? -cp.m_normalWorldOnB : cp.m_normalWorldOnB;
                const btTransform inv = target->rb->getWorldTransform().inverse();
                const btVector3 lp = inv * pt;
                const btVector3 ln = inv.getBasis() * nrm;
                rubble::Impact imp{{lp.x(), lp.y(), lp.z()}, {ln.x(), ln.y(), ln.z()}, maxImpulse};
                if (destruction_->submitImpact(target->object, imp)) {
                    ++counters_.submitted;
                    marks_.push_back({toV3(pt), toV3(nrm), 0});
                }
            }
        }
#endif
    }
}

void Game::spawnPiece(const Body& parent, const rubble::Mesh& mesh, const rubble::Mat3& rotation,
                      const rubble::Vec3& offset, double volume, const rubble::Vec3& inertiaDiag,
                      double density, std::uint32_t object,
                      const std::vector<std::vector<rubble::Vec3>>& partsIn, Renderer& renderer) {
    const btTransform T = parent.rb->getWorldTransform();
    const btVector3 v = parent.rb->getLinearVelocity();
    const btVector3 w = parent.rb->getAngularVelocity();
    btMatrix3x3 basis;
    for (int r = 0; r < 3; ++r)
        basis[r] = btVector3(static_cast<btScalar>(rotation.m[r][0]), static_cast<btScalar>(rotation.m[r][1]),
                             static_cast<btScalar>(rotation.m[r][2]));
    const btTransform Tp = T * btTransform(basis, toBt(offset));
    const btVector3 r = Tp.getOrigin() - T.getOrigin();
    const btVector3 pv = v + w.cross(r);
    if (volume < settings_.minPieceVolume) {
        particles_.debrisPuff(toV3(Tp.getOrigin()), toV3(pv) + toV3(r.normalized()) * 2.0f,
                              static_cast<float>(std::cbrt(volume)), burstSeed_++);
        ++counters_.retired;
        return;
    }
    auto b = std::make_unique<Body>();
    b->kind = Body::Kind::Piece;
    b->object = object;
    b->volume = static_cast<float>(volume);
    b->density = density;
    b->texture = parent.texture;
    b->tint = parent.tint;
    b->heat = 1.0f;
#if !RUBBLE_DEMO_HAS_RUNTIME
    b->localMesh = mesh;
#endif
    auto compound = std::make_unique<btCompoundShape>();
    std::vector<std::vector<rubble::Vec3>> parts = partsIn;
    if (parts.empty())
        parts.push_back(mesh.positions);
    for (const auto& pts : parts) {
        auto hull = std::make_unique<btConvexHullShape>();
        for (const auto& p : pts)
            hull->addPoint(toBt(p), false);
        hull->recalcLocalAabb();
        hull->setMargin(0.01f);
        btTransform id;
        id.setIdentity();
        compound->addChildShape(id, hull.get());
        b->children.push_back(std::move(hull));
    }
    b->shape = std::move(compound);
    const bool staysStatic = parent.rb->getInvMass() == 0 && volume > 0.25 * parent.volume;
    const float mass = staysStatic ? 0.0f : static_cast<float>(density * volume);
    btVector3 inertia(0, 0, 0);
    if (mass > 0)
        inertia = btVector3(static_cast<btScalar>(std::max(1e-6, inertiaDiag.x * density)),
                            static_cast<btScalar>(std::max(1e-6, inertiaDiag.y * density)),
                            static_cast<btScalar>(std::max(1e-6, inertiaDiag.z * density)));
    b->rb = std::make_unique<btRigidBody>(
        btRigidBody::btRigidBodyConstructionInfo(mass, nullptr, b->shape.get(), inertia));
    b->rb->setWorldTransform(Tp);
    b->rb->setFriction(0.8f);
    b->rb->setDamping(0.05f, 0.2f);
    if (mass > 0) {
        b->rb->setLinearVelocity(pv);
        b->rb->setAngularVelocity(w);
    }
    b->mesh = renderer.addMesh(mesh, b->texture, b->tint.x, b->tint.y, b->tint.z);
    addBody(std::move(b));
    ++counters_.piecesCreated;
}

void Game::adoptFractures(Renderer& renderer) {
#if !RUBBLE_DEMO_HAS_RUNTIME
    local_.deterministic = settings_.deterministic;
    for (auto& res : local_.collect(counters_.frame)) {
        Body* parent = nullptr;
        for (auto& b : bodies_)
            if (b->object == res.key && !b->dead && b->kind != Body::Kind::Projectile)
                parent = b.get();
        if (!parent || res.pieces.empty())
            continue;
        for (auto& piece : res.pieces) {
            const std::uint32_t id = piece.volume >= settings_.minPieceVolume ? nextLocalId_++ : 0;
            spawnPiece(*parent, piece.mesh, rubble::Mat3::identity(), piece.offset, piece.volume,
                       piece.inertia, parent->density, id, {}, renderer);
        }
        latencies_.push_back(res.latencyMs);
        parent->dead = true;
        removeBody(parent, renderer);
        ++counters_.fractures;
    }
    counters_.jobs = local_.inFlight();
#endif
#if RUBBLE_DEMO_HAS_RUNTIME
    destruction_->beginFrame();
    auto outcomes = destruction_->collect();
    for (auto& o : outcomes) {
        Body* parent = nullptr;
        for (auto& b : bodies_)
            if (b->object == o.parent && !b->dead && b->kind != Body::Kind::Projectile)
                parent = b.get();
        if (!parent) {
            for (auto id : o.pieces)
                destruction_->removeObject(id);
            continue;
        }
        for (size_t i = 0; i < o.pieces.size() && i < o.pieceFrames.size(); ++i) {
            const rubble::ObjectState* st = destruction_->object(o.pieces[i]);
            if (!st)
                continue;
            const double vol = std::fabs(st->mass.volume);
            std::vector<std::vector<rubble::Vec3>> parts;
            for (const auto& part : st->convexParts)
                parts.push_back(part.vertices());
            const rubble::Vec3 inertia{st->mass.inertia.m[0][0], st->mass.inertia.m[1][1],
                                       st->mass.inertia.m[2][2]};
            if (vol < settings_.minPieceVolume)
                destruction_->removeObject(o.pieces[i]);
            spawnPiece(*parent, st->mesh, o.pieceFrames[i].rotation, o.pieceFrames[i].translation, vol,
                       inertia, st->density, vol < settings_.minPieceVolume ? 0 : o.pieces[i], parts,
                       renderer);
        }
        parent->dead = true;
        removeBody(parent, renderer);
        ++counters_.fractures;
    }
    const auto& timings = destruction_->timings();
    for (; timingCursor_ < timings.size(); ++timingCursor_)
        if (!timings[timingCursor_].stale)
            latencies_.push_back(timings[timingCursor_].totalMs);
    counters_.jobs = destruction_->jobsInFlight();
#else
    (void)renderer;
#endif
}

void Game::retireExcessPieces(Renderer& renderer) {
    std::vector<Body*> pieces;
    for (auto& b : bodies_)
        if (b->kind == Body::Kind::Piece)
            pieces.push_back(b.get());
    counters_.pieces = static_cast<int>(pieces.size());
    if (static_cast<int>(pieces.size()) <= settings_.maxPieces)
        return;
    std::sort(pieces.begin(), pieces.end(), [](Body* x, Body* y) { return x->volume < y->volume; });
    const size_t excess = pieces.size() - static_cast<size_t>(settings_.maxPieces);
    for (size_t i = 0; i < excess && i < pieces.size(); ++i) {
        Body* p = pieces[i];
        if (p->age < 1.0f || p->rb->getInvMass() == 0)
            continue;
        particles_.debrisPuff(toV3(p->rb->getCenterOfMassPosition()), toV3(p->rb->getLinearVelocity()),
                              std::cbrt(p->volume), burstSeed_++);
#if RUBBLE_DEMO_HAS_RUNTIME
        destruction_->removeObject(p->object);
#endif
        removeBody(p, renderer);
        ++counters_.retired;
    }
}

void Game::step(const ControlInput& input, float dt, Renderer& renderer) {
    if (!world_)
        return;
    time_ += dt;
    ++counters_.frame;
    controlVehicle(input, dt);
    fireCooldown_ -= dt;
    if (input.fire && vehicle_ && (!fireWasDown_ || fireCooldown_ <= 0)) {
        fire(renderer);
        fireCooldown_ = settings_.fireInterval;
    }
    fireWasDown_ = input.fire;

    world_->stepSimulation(dt, 0);
    processContacts(renderer);

    // Projectiles: trails, lifetime; dead ones removed.
    std::vector<Body*> doomed;
    for (auto& b : bodies_) {
        b->age += dt;
        b->heat = std::max(0.0f, b->heat - dt * 0.6f);
        if (b->kind == Body::Kind::Projectile) {
            const V3 p = toV3(b->rb->getCenterOfMassPosition());
            particles_.emit(ParticleSystem::Kind::Trail, p, V3{}, 0.18f, 0.5f, 1.0f, 0.7f, 0.3f);
            if (b->dead || b->age > 3.0f || p.y < groundTop_ - 5)
                doomed.push_back(b.get());
        } else if (b->kind == Body::Kind::Piece && b->rb->getCenterOfMassPosition().y() < groundTop_ - 60) {
            doomed.push_back(b.get());
        }
    }
    for (Body* b : doomed) {
#if RUBBLE_DEMO_HAS_RUNTIME
        if (b->kind == Body::Kind::Piece)
            destruction_->removeObject(b->object);
#endif
        removeBody(b, renderer);
    }

    adoptFractures(renderer);
    retireExcessPieces(renderer);
    particles_.step(dt, groundTop_);
    for (auto& m : marks_)
        m.age += dt;
    while (!marks_.empty() && marks_.front().age > 4.0f)
        marks_.pop_front();
    counters_.bodies = static_cast<int>(bodies_.size());
}

void Game::draw(Renderer& renderer, float dt) {
    if (!world_)
        return;
    renderer.shadows = settings_.shadows;
    for (auto& b : bodies_) {
        if (b->kind == Body::Kind::Projectile) {
            Particle p;
            p.pos = toV3(b->rb->getCenterOfMassPosition());
            p.size = 1.4f;
            p.r = 1.0f;
            p.g = 0.85f;
            p.b = 0.45f;
            renderer.addParticle(p, true);
            continue;
        }
        if (b->mesh < 0)
            continue;
        M4 m;
        b->rb->getWorldTransform().getOpenGLMatrix(m.m);
        renderer.drawMesh(b->mesh, m, b->heat);
    }
    if (vehicle_) {
        // Engine glow at the tail.
        const btTransform& t = vehicle_->rb->getWorldTransform();
        Particle p;
        p.pos = toV3(t * btVector3(0, 0, noseOffset_ - 2.2f));
        p.size = 1.1f + 0.02f * speed_;
        p.r = 0.5f;
        p.g = 0.75f;
        p.b = 1.0f;
        p.a = 0.9f;
        renderer.addParticle(p, true);
    }
    particles_.draw(renderer);

    if (settings_.debugShapes || settings_.debugAabbs) {
        DebugLines dl(renderer);
        int mode = 0;
        if (settings_.debugShapes)
            mode |= btIDebugDraw::DBG_DrawWireframe;
        if (settings_.debugAabbs)
            mode |= btIDebugDraw::DBG_DrawAabb;
        dl.setDebugMode(mode);
        world_->setDebugDrawer(&dl);
        world_->debugDrawWorld();
        world_->setDebugDrawer(nullptr);
    }
    if (settings_.debugImpacts)
        for (const auto& m : marks_) {
            const float s = 1.5f;
            renderer.addLine(m.point - V3{s, 0, 0}, m.point + V3{s, 0, 0}, 1, 0.1f, 0.1f);
            renderer.addLine(m.point - V3{0, s, 0}, m.point + V3{0, s, 0}, 1, 0.1f, 0.1f);
            renderer.addLine(m.point - V3{0, 0, s}, m.point + V3{0, 0, s}, 1, 0.1f, 0.1f);
            renderer.addLine(m.point, m.point + m.normal * 3.0f, 1, 1, 0.2f);
        }

    V3 pos, fwd, up;
    vehicleFrame(pos, fwd, up);
    camera_.update(pos, fwd, up, dt);
    camera_.eye.y = std::max(camera_.eye.y, groundTop_ + 1.5f);
}

std::vector<double> Game::takeNewLatencies() {
    std::vector<double> out(latencies_.begin() + static_cast<long>(latencyCursor_), latencies_.end());
    latencyCursor_ = latencies_.size();
    return out;
}

std::vector<V3> Game::targets() const {
    std::vector<V3> out;
    for (const auto& b : bodies_)
        if (!b->dead &&
            (b->kind == Body::Kind::Object || (b->kind == Body::Kind::Piece && b->volume > 150 &&
                                               b->rb->getCenterOfMassPosition().y() > groundTop_ + 15)))
            out.push_back(toV3(b->rb->getCenterOfMassPosition()));
    return out;
}

void Game::writeTimings(const std::string& path) const {
#if RUBBLE_DEMO_HAS_RUNTIME
    if (destruction_)
        (void)destruction_->writeTimingsCsv(path);
#else
    (void)path;
#endif
}

} // namespace demo
