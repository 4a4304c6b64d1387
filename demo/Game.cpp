#include "Game.hpp"

#include "GroundMesh.hpp"

#include "rubble/rubble.hpp"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "rubble/bullet/Convert.hpp"

namespace demo {

namespace {

using rubble::BodyId;
using rubble::BodyRecord;
using rubble::BodyRole;

V3 toV3(const btVector3& v) {
    return {v.x(), v.y(), v.z()};
}
V3 toV3(const rubble::Vec3& v) {
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
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

/// The game's impact settings in the runtime's policy.
void applyImpactSettings(rubble::ImpactPolicy& impacts, const GameSettings& settings) {
    impacts.collisionImpulseThreshold = settings.collisionImpulse;
    impacts.blastCutVolume = settings.blastCutVolume;
    impacts.collisionFracturesPerSecond = settings.collisionFractureRate;
    impacts.blastMaxCuts = settings.blastMaxCuts;
}

} // namespace

Game::Game() = default;

Game::~Game() {
    if (runtime_) {
        runtime_->setOnRemoved({});
        runtime_->setOnAdopted({});
    }
    runtime_.reset();
    binding_.reset();
    physics_.reset();
}

void Game::clear(Renderer& renderer) {
    if (runtime_) {
        runtime_->setOnAdopted({});
        runtime_->setOnRemoved({});
    }
    for (const auto& [body, v] : visuals_)
        if (v.mesh >= 0)
            renderer.removeMesh(v.mesh);
    visuals_.clear();
    looks_.clear();
    vehicle_ = 0;
    net_.reset();
    runtime_.reset();
    binding_.reset();
    physics_.reset();
    particles_.clear();
    counters_ = {};
    latencies_.clear();
    latencyCursor_ = 0;
    visible_.clear();
    nextTiming_ = 0;
    shells_.clear();
    landed_.clear();
    stepImpacts_.clear();
    hitBy_.clear();
    sounds_.clear();
    lastKnock_.clear();
    heard_ = {};
    blastBy_ = -1;
}

void Game::addVisual(BodyId body, const rubble::Mesh& mesh, const Look& look, float heat,
                     Renderer& renderer) {
    Visual v;
    v.mesh = renderer.addMesh(mesh, look.texture, look.tint.x, look.tint.y, look.tint.z, look.interior);
    v.heat = heat;
    v.tint = look.tint;
    visuals_[body] = v;
}

bool Game::load(const rubble::SceneConfig& scene, Renderer& renderer, const GameSettings& settings,
                std::vector<std::string>& warnings, std::string& error) {
    clear(renderer);
    settings_ = settings;
    renderer.shadows = settings.shadows;
    particles_.dustDensity = renderer.quality().software ? 0.35f : 1.0f;
    rubble::DestructionRuntime::Config rc;
    jobs_.reset();
    jobs_ = std::make_unique<PriorityJobs>(settings.workers, settings.workerNice);
    rc.world.jobs = jobs_.get();
    rc.world.workers = settings.workers;
    rc.world.deterministic = settings.deterministic;
    rc.world.seed = 20260522;
    rc.world.minPieceVolume = settings.minPieceVolume;
    applyImpactSettings(rc.impacts, settings);
    rc.debris.maxAwakeBodies = settings.maxAwake;
    rc.debris.lightPerAwake = settings.lightPerAwake;
    rc.support.collapseUnsupported = settings.collapseUnsupported;
    rc.structure.enabled = settings.structure;
    rc.projectileLifetime = 3;
    rc.spentProjectileLifetime = 0;
    physics_ = std::make_unique<rubble::bullet::PhysicsWorld>();
    binding_ = std::make_unique<rubble::bullet::BulletBinding>(*physics_);
    runtime_ = std::make_unique<rubble::DestructionRuntime>(*binding_, rc);
    worldConfig_ = rc.world;
    journal_.clear();
    runtime_->setJournalSink([this](const rubble::JournalEvent& e) { journaled(e); });
    runtime_->setOnRemoved([this, &renderer](const BodyRecord& b) {
        if (auto shell = shells_.find(b.id); shell != shells_.end()) { // a shell's hit is known when it goes
            if (b.spent)
                landed_.push_back(
                    {shell->second.weapon, toV3(runtime_->motion(b.id).transform.translation), true});
            shells_.erase(shell);
        }
        lastKnock_.erase(b.id);
        auto it = visuals_.find(b.id);
        if (it == visuals_.end())
            return;
        if (it->second.mesh >= 0)
            renderer.removeMesh(it->second.mesh);
        visuals_.erase(it);
    });
    runtime_->setOnAdopted([this, &renderer](const rubble::FractureOutcome& o) { onAdopted(o, renderer); });

    rubble::SceneLoadOptions lo;
    lo.loadVehicle = false; // the demo builds its own (stand-in jet, steering assist)
    lo.staticDensity = 400;
    lo.impulseThreshold = settings.impulseThreshold;
    lo.fracture = settings.fracture;
    lo.materialRoughness = settings.roughCuts;
    lo.prepareMesh = [](rubble::Mesh& m) {
        m.normals.clear();
        ensureUvs(m, 4.0);
    };
    const rubble::LoadedScene loaded = rubble::loadScene(scene, *runtime_, lo);
    for (const auto& w : loaded.warnings)
        warnings.push_back(w);
    notePlacedDynamic();

    // Ground: a solid unit cube scaled (thesis: "generated as a solid cube with 1x1x1 size").
    if (loaded.ground) {
        const auto& g = scene.ground;
        const rubble::Vec3 half{std::abs(g.scale.x) * 0.5, std::abs(g.scale.y) * 0.5,
                                std::abs(g.scale.z) * 0.5};
        const rubble::Mesh box = groundMesh(g);
        binding_->rigid(loaded.ground)->setFriction(0.9f);
        Look look;
        look.texture = g.textureFound ? renderer.loadTexture(g.texturePath, "grid", warnings)
                                      : renderer.proceduralTexture("grid");
        look.tint = {0.95f, 1.0f, 0.92f};
        addVisual(loaded.ground, box, look, 0, renderer);
        groundTop_ = static_cast<float>(loaded.groundTop);
        groundBody_ = loaded.ground;
        boundsMinX_ = static_cast<float>(g.position.x - half.x);
        boundsMaxX_ = static_cast<float>(g.position.x + half.x);
        boundsMinZ_ = static_cast<float>(g.position.z - half.z);
        boundsMaxZ_ = static_cast<float>(g.position.z + half.z);
    }
    rubble::DebrisBudget debris = runtime_->config().debris;
    debris.killBelowY = groundTop_ - 60.0;
    runtime_->setDebrisBudget(debris);

    // Vehicle: the scene's model, or the built-in jet; an indestructible convex body steered by
    // controlVehicle.
    if (scene.vehicle.line != 0) {
        const auto& v = scene.vehicle;
        rubble::Mesh mesh;
        bool standIn = true;
        if (v.modelFound) {
            auto r = rubble::readMesh(v.modelPath);
            if (r && !r->empty()) {
                mesh = r.value().transformed(rubble::Mat3::identity(), v.scale, {0, 0, 0});
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
        auto body = runtime_->addConvexBody(
            mesh.positions, rubble::Frame{rubble::Mat3::identity(), v.position}, std::max(v.mass, 1.0), true);
        if (body) {
            vehicle_ = *body;
            btRigidBody* rb = binding_->rigid(vehicle_);
            rb->setFlags(rb->getFlags() | BT_DISABLE_WORLD_GRAVITY);
            rb->setGravity(btVector3(0, 0, 0));
            rb->setActivationState(DISABLE_DEACTIVATION);
            rb->setDamping(0.05f, 0.6f);
            Look look;
            look.texture = v.textureFound ? renderer.loadTexture(v.texturePath, "metal", warnings)
                                          : renderer.proceduralTexture("metal");
            look.tint = {0.85f, 0.9f, 1.0f};
            addVisual(vehicle_, mesh, look, 0, renderer);
            hover_ = v.mass <= 0; // the thesis's static vehicle (mass 0) hovers: no stall floor
            speed_ = hover_ ? 0.0f : 30.0f;
            spawnPos_ = toV3(v.position);
            rb->setLinearVelocity(btVector3(0, 0, -speed_));
        } else {
            warnings.push_back(scene.baseDir.string() + ":" + std::to_string(v.line) + ": vehicle skipped (" +
                               body.error().message + ")");
        }
    }

    // Objects: render meshes in object coordinates (the runtime's mesh, UVs included).
    for (size_t i = 0; i < loaded.objects.size(); ++i) {
        const rubble::ObjectId id = loaded.objects[i];
        const auto& o = scene.objects[loaded.sceneIndex[i]];
        const BodyRecord* body = runtime_->bodyOf(id);
        const rubble::ObjectState* st = runtime_->world().object(id);
        if (!body || !st)
            continue;
        btRigidBody* rb = binding_->rigid(body->id);
        rb->setFriction(0.8f);
        rb->setDamping(0.02f, 0.1f);
        Look look;
        look.texture = o.textureFound ? renderer.loadTexture(o.texturePath, "concrete", warnings)
                                      : renderer.proceduralTexture("concrete");
        if (!o.material.empty()) // cut faces show the material's grain
            look.interior = renderer.materialInterior(o.material);
        look.timbre = timbreOf(o.material);
        looks_[id] = look;
        addVisual(body->id, st->mesh, look, 0, renderer);
    }
    counters_.warnings = static_cast<int>(warnings.size());
    { // showcase camera: in front of the objects' centre, at a distance that frames their spread
        const std::vector<V3> t = targets();
        V3 c{};
        for (const V3& p : t)
            c = c + p * (1.0f / static_cast<float>(std::max<std::size_t>(t.size(), 1)));
        float r = 5;
        for (const V3& p : t)
            r = std::max(r, len(p - c));
        showcaseAt_ = c;
        showcaseEye_ = c + V3{0.9f, 0.45f, 1.6f} * (1.1f * r + 6);
        showcaseEye_.y = std::max(showcaseEye_.y, groundTop_ + 3);
    }
    V3 pos, fwd, up;
    vehicleFrame(pos, fwd, up);
    camera_.snap(pos, fwd, up);
    (void)error;
    return true;
}

void Game::onAdopted(const rubble::FractureOutcome& o, Renderer& renderer) {
    if (auto hit = hitBy_.find(o.parent); hit != hitBy_.end()) {
        ++counters_.weaponFractures[static_cast<std::size_t>(hit->second)];
        hitBy_.erase(hit);
    }
    Look look;
    if (auto it = looks_.find(o.parent); it != looks_.end()) {
        look = it->second;
        looks_.erase(it);
    }
    for (const rubble::AdoptedPiece& piece : o.pieces) {
        const BodyRecord* b = runtime_->bodyOf(piece.id);
        if (!b)
            continue;
        btRigidBody* rb = binding_->rigid(b->id);
        rb->setFriction(0.8f);
        rb->setDamping(0.05f, 0.2f);
        looks_[piece.id] = look;
        addVisual(b->id, piece.state->mesh, look, 1.0f, renderer);
    }
}

void Game::effectsOfEvents() {
    // one break sound per split: at its pieces' centre of mass, as loud as the impulse, as low as it is big
    const auto& made = runtime_->createdPieces();
    for (std::size_t i = heard_.pieces; i < made.size();) {
        const rubble::PieceCreated& first = made[i];
        SoundEvent e{SoundKind::Break, timbreOf(first.material)};
        e.impulse = static_cast<float>(first.impulse);
        double mass = 0, volume = 0;
        rubble::Vec3 centre{};
        for (; i < made.size() && made[i].parent == first.parent; ++i) {
            mass += made[i].mass;
            volume += made[i].volume;
            centre = centre + made[i].position * made[i].mass;
        }
        if (mass > 0) {
            e.position = toV3(centre * (1.0 / mass));
            e.size = static_cast<float>(std::cbrt(volume));
            sound(e);
        }
    }
    heard_.pieces = made.size();
    // a dust cloud where a bond broke, as wide as its section
    const auto& broke = runtime_->structureBreaks();
    for (std::size_t i = heard_.breaks; i < broke.size(); ++i)
        particles_.debrisPuff(toV3(broke[i].position), V3{},
                              0.5f * static_cast<float>(std::sqrt(broke[i].area)), burstSeed_++);
    heard_.breaks = broke.size();
    // one rumble for the bodies that began to fall: their mass at 3 m/s, their volume; dust where each let go
    const auto& falls = runtime_->structureCollapses();
    if (heard_.collapses >= falls.size())
        return;
    SoundEvent e{SoundKind::Collapse, timbreOf(falls[heard_.collapses].material)};
    double mass = 0, volume = 0;
    rubble::Vec3 centre{};
    for (std::size_t i = heard_.collapses; i < falls.size(); ++i) {
        mass += falls[i].mass;
        volume += falls[i].volume;
        centre = centre + falls[i].position * falls[i].mass;
        particles_.debrisPuff(toV3(falls[i].position), V3{}, static_cast<float>(std::cbrt(falls[i].volume)),
                              burstSeed_++);
    }
    heard_.collapses = falls.size();
    if (!(mass > 0))
        return;
    e.position = toV3(centre * (1.0 / mass));
    e.impulse = static_cast<float>(3.0 * mass);
    e.size = static_cast<float>(std::cbrt(volume));
    sound(e);
}

void Game::sound(const SoundEvent& e) {
    sounds_.push_back(e);
    ++counters_.sounds[static_cast<std::size_t>(e.kind)];
}

std::vector<SoundEvent> Game::takeSounds() {
    std::vector<SoundEvent> out;
    out.swap(sounds_);
    return out;
}

void Game::listenForDebris() {
    // A body that meets the ground with a velocity change over 1.5 m/s knocks (at most every 0.25 s).
    constexpr float kKnockDeltaV = 1.5f;
    constexpr std::uint64_t kKnockFrames = 15;
    if (!groundBody_)
        return;
    const btCollisionObject* ground = binding_->rigid(groundBody_);
    btDispatcher* dispatcher = physics_->world().getDispatcher();
    for (int i = 0, n = dispatcher->getNumManifolds(); i < n; ++i) {
        const btPersistentManifold* m = dispatcher->getManifoldByIndexInternal(i);
        const btCollisionObject* other = m->getBody0() == ground   ? m->getBody1()
                                         : m->getBody1() == ground ? m->getBody0()
                                                                   : nullptr;
        if (!other || m->getNumContacts() == 0)
            continue;
        const auto id = static_cast<BodyId>(other->getUserIndex());
        const BodyRecord* b = runtime_->body(id);
        if (!b || b->mass <= 0 || (b->role != BodyRole::Piece && b->role != BodyRole::Object))
            continue;
        float impulse = 0;
        for (int k = 0; k < m->getNumContacts(); ++k)
            impulse += m->getContactPoint(k).getAppliedImpulse();
        if (impulse < kKnockDeltaV * static_cast<float>(b->mass))
            continue;
        auto [last, fresh] = lastKnock_.try_emplace(id, counters_.frame);
        if (!fresh && counters_.frame - last->second < kKnockFrames)
            continue;
        last->second = counters_.frame;
        SoundEvent e{SoundKind::Debris, Timbre::Stone};
        if (b->hasObject)
            if (auto look = looks_.find(b->object); look != looks_.end())
                e.timbre = look->second.timbre;
        e.position = toV3(m->getContactPoint(0).getPositionWorldOnB());
        e.impulse = impulse;
        e.size = static_cast<float>(std::cbrt(b->volume));
        sound(e);
    }
}

void Game::vehicleFrame(V3& pos, V3& forward, V3& up) const {
    if (!vehicle_) {
        pos = {};
        forward = {0, 0, -1};
        up = {0, 1, 0};
        return;
    }
    const btTransform& t = binding_->rigid(vehicle_)->getWorldTransform();
    pos = toV3(t.getOrigin());
    forward = toV3(t.getBasis() * btVector3(0, 0, -1));
    up = toV3(t.getBasis() * btVector3(0, 1, 0));
}

void Game::respawn() {
    if (!vehicle_)
        return;
    btRigidBody* rb = binding_->rigid(vehicle_);
    rb->setCollisionFlags(rb->getCollisionFlags() & ~btCollisionObject::CF_NO_CONTACT_RESPONSE);
    btTransform t;
    t.setIdentity();
    t.setOrigin(btVector3(spawnPos_.x, std::max(spawnPos_.y, groundTop_ + 25.0f), spawnPos_.z));
    rb->setWorldTransform(t);
    rb->setInterpolationWorldTransform(t);
    if (rb->getMotionState())
        rb->getMotionState()->setWorldTransform(t);
    speed_ = hover_ ? 0.0f : 30.0f;
    rb->setLinearVelocity(btVector3(0, 0, -speed_));
    rb->setAngularVelocity(btVector3(0, 0, 0));
    rb->activate(true);
    crashTimer_ = 0;
    ++counters_.respawns;
    V3 pos, fwd, up;
    vehicleFrame(pos, fwd, up);
    camera_.snap(pos, fwd, up);
}

void Game::blast(const V3& point, float radius, float impulse, int by) {
    blastBy_ = by;
    counters_.blastThrown += runtime_->blast(rubble::Vec3{point.x, point.y, point.z}, radius, impulse).thrown;
    blastBy_ = -1;
    particles_.impactBurst(point, V3{0, 1, 0}, 3.0f, burstSeed_++);
    particles_.impactBurst(point, V3{0, 1, 0}, 2.0f, burstSeed_++);
}

bool Game::blastNextTarget() {
    const std::vector<V3> standing = targets();
    if (standing.empty())
        return false;
    const WeaponSpec& charge = weaponSpec(Weapon::Charge);
    blast(standing[nextTarget_++ % standing.size()], charge.blastRadius, charge.blastImpulse,
          static_cast<int>(Weapon::Charge));
    return true;
}

bool Game::hitAt(const V3& point, float impulse) {
    return runtime_ &&
           runtime_->blast(rubble::Vec3{point.x, point.y, point.z}, 0.01, impulse, 1.0).impacts > 0;
}

void Game::checkCrash() {
    if (!vehicle_ || crashTimer_ > 0)
        return;
    const btRigidBody* jet = binding_->rigid(vehicle_);
    btCollisionDispatcher& d = physics_->dispatcher();
    for (int i = 0; i < d.getNumManifolds(); ++i) {
        const btPersistentManifold* m = d.getManifoldByIndexInternal(i);
        if (m->getNumContacts() == 0 || (m->getBody0() != jet && m->getBody1() != jet))
            continue;
        const btCollisionObject* other = m->getBody0() == jet ? m->getBody1() : m->getBody0();
        bool hard = groundBody_ && other == binding_->rigid(groundBody_);
        if (!hard)
            for (BodyId id : runtime_->bodies()) { // objects, and pieces bigger than a car
                const BodyRecord* b = runtime_->body(id);
                if (binding_->rigid(id) == other)
                    hard = b->role == BodyRole::Object || (b->role == BodyRole::Piece && b->volume > 2.0);
            }
        bool touching = false;
        btVector3 at(0, 0, 0);
        for (int c = 0; c < m->getNumContacts(); ++c)
            if (m->getContactPoint(c).getDistance() < 0.05f) {
                touching = true;
                at = m->getContactPoint(c).getPositionWorldOnA();
            }
        if (!hard || !touching)
            continue;
        // Crash: the wreck stops, explodes (damaging what it hit and what is near) and respawns in 2 s.
        ++counters_.crashes;
        crashTimer_ = 2.0f;
        btRigidBody* rb = binding_->rigid(vehicle_);
        rb->setCollisionFlags(rb->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
        rb->setLinearVelocity(btVector3(0, 0, 0));
        rb->setAngularVelocity(btVector3(0, 0, 0));
        blast(toV3(at), 10.0f, 4000.0f);
        return;
    }
}

void Game::controlVehicle(const ControlInput& input, float dt) {
    if (!vehicle_)
        return;
    btRigidBody* rb = binding_->rigid(vehicle_);
    if (crashTimer_ > 0) { // wrecked: stays put until the respawn
        rb->setLinearVelocity(btVector3(0, 0, 0));
        rb->setAngularVelocity(btVector3(0, 0, 0));
        crashTimer_ -= dt;
        if (crashTimer_ <= 0)
            respawn();
        return;
    }
    ControlInput in = input;
    const btMatrix3x3& R = rb->getWorldTransform().getBasis();
    const btVector3 pos = rb->getWorldTransform().getOrigin();
    const btVector3 fwd = R * btVector3(0, 0, -1);
    // World bounds: within 150 m of the ground's edge (or 350 m above it) the controls blend into a turn
    // back toward the middle, the harder the farther out.
    const float margin = 150.0f;
    const float cx = 0.5f * (boundsMinX_ + boundsMaxX_), cz = 0.5f * (boundsMinZ_ + boundsMaxZ_);
    const float out = std::max({boundsMinX_ + margin - pos.x(), pos.x() - (boundsMaxX_ - margin),
                                boundsMinZ_ + margin - pos.z(), pos.z() - (boundsMaxZ_ - margin), 0.0f});
    const btVector3 toCentre = btVector3(cx - pos.x(), 0, cz - pos.z()).safeNormalize();
    const bool wasTurning = turningBack_;
    turningBack_ = out > 0 && btVector3(fwd.x(), 0, fwd.z()).dot(toCentre) < 0.7f;
    if (turningBack_) {
        const float w = std::clamp(0.35f + out / margin, 0.0f, 1.0f);
        const float side = (R * btVector3(1, 0, 0)).dot(toCentre); // > 0: the centre is to the right
        in.yaw = in.yaw * (1 - w) + (side > 0 ? -1.0f : 1.0f) * w;
        in.roll = in.roll * (1 - w);
        if (!wasTurning)
            ++counters_.turnBacks;
    }
    if (pos.y() > groundTop_ + 350.0f && fwd.y() > -0.2f)
        in.pitch = 1.0f;
    speed_ = std::clamp(speed_ + in.throttle * 25.0f * dt, hover_ ? 0.0f : kStallSpeed, 90.0f);
    const btVector3 right = R * btVector3(1, 0, 0);
    // Stabilising assist (auto-level, L): without roll input the wings level themselves.
    const float level =
        settings_.autoLevel ? -right.y() * 1.6f * (1.0f - std::min(1.0f, std::fabs(in.roll))) : 0.0f;
    const btVector3 localRate(-in.pitch * 1.1f, in.yaw * 1.0f, in.roll * 2.0f + level);
    const btVector3 target = R * localRate;
    btVector3 w = rb->getAngularVelocity();
    // Angular velocity is driven to the commanded rate: a collision cannot leave the vehicle spinning.
    w += (target - w) * (1.0f - std::exp(-10.0f * dt));
    rb->setAngularVelocity(w);
    btVector3 v = rb->getLinearVelocity();
    v += (fwd * speed_ - v) * (1.0f - std::exp(-2.5f * dt));
    rb->setLinearVelocity(v);
    rb->activate(true);
}

V3 Game::shotVelocity() const {
    if (!vehicle_)
        return {};
    const btRigidBody* vehicle = binding_->rigid(vehicle_);
    const btVector3 fwd = vehicle->getWorldTransform().getBasis() * btVector3(0, 0, -1);
    const bool cannon = weapon_ == Weapon::Cannon; // the cannon follows the panel's projectile settings
    return toV3(vehicle->getLinearVelocity() +
                fwd * (cannon ? settings_.projectileSpeed : weaponSpec(weapon_).speed));
}

void Game::fire() {
    const btRigidBody* vehicle = binding_->rigid(vehicle_);
    const btTransform& vt = vehicle->getWorldTransform();
    const btVector3 fwd = vt.getBasis() * btVector3(0, 0, -1);
    const btVector3 from = vt.getOrigin() + fwd * noseOffset_;
    const V3 v = shotVelocity();
    launch(from, btVector3(v.x, v.y, v.z), weapon_);
}

void Game::launch(const btVector3& from, const btVector3& velocity, Weapon weapon) {
    const WeaponSpec& w = weaponSpec(weapon);
    const BodyId p =
        runtime_->fireProjectile(rubble::bullet::fromBt(from), rubble::bullet::fromBt(velocity),
                                 weapon == Weapon::Cannon ? settings_.projectileMass : w.mass, w.radius);
    btRigidBody* rb = binding_->rigid(p);
    rb->setFlags(rb->getFlags() | BT_DISABLE_WORLD_GRAVITY);
    rb->setGravity(btVector3(0, -2.0f, 0));
    shells_[p] = {weapon, {}, false};
    ++counters_.shots;
    ++counters_.weaponShots[static_cast<std::size_t>(weapon)];
}

bool Game::shootNextTarget(const V3& from) {
    const std::vector<V3> all = shellTargets();
    if (all.empty())
        return false;
    const V3 target = all[nextShot_++ % all.size()];
    const V3 toward = from - target;
    const V3 dir = len(toward) > 1e-3f ? norm(toward) : V3{0, 0, 1};
    const V3 muzzle = target + dir * 40.0f;
    const V3 v = dir * -settings_.projectileSpeed;
    launch(btVector3(muzzle.x, muzzle.y, muzzle.z), btVector3(v.x, v.y, v.z), Weapon::Cannon);
    return true;
}

void Game::journaled(const rubble::JournalEvent& e) {
    journal_.push_back(e);
    if (net_)
        net_->journaled(e);
    if (e.kind != rubble::JournalEventKind::Impact)
        return;
    if (const BodyRecord* b = runtime_->bodyOf(e.object)) { // an impact sounds where it hit
        const btTransform objectToWorld =
            binding_->rigid(b->id)->getWorldTransform() * rubble::bullet::toBt(b->objectToBody).inverse();
        SoundEvent s{SoundKind::Impact, Timbre::Stone};
        if (auto look = looks_.find(e.object); look != looks_.end())
            s.timbre = look->second.timbre;
        s.position = toV3(objectToWorld * btVector3(e.point[0], e.point[1], e.point[2]));
        s.impulse = e.impulse;
        s.size = static_cast<float>(std::cbrt(b->volume));
        sound(s);
    }
    if (blastBy_ >= 0)
        hitBy_[e.object] = blastBy_;
    else
        stepImpacts_.push_back(e);
}

void Game::creditHits() {
    // Each impact of the step goes to the weapon of the nearest shell that hit something in it; impacts
    // without a shell (falling pieces, a crash) count for no weapon.
    for (const rubble::JournalEvent& e : stepImpacts_) {
        if (landed_.empty())
            break;
        const Shell* best = landed_.size() == 1 ? &landed_.front() : nullptr;
        if (const BodyRecord* b = runtime_->bodyOf(e.object)) {
            const btTransform objectToWorld =
                binding_->rigid(b->id)->getWorldTransform() * rubble::bullet::toBt(b->objectToBody).inverse();
            const V3 at = toV3(objectToWorld * btVector3(e.point[0], e.point[1], e.point[2]));
            float nearest = 1e30f;
            for (const Shell& s : landed_)
                if (len(s.at - at) < nearest) {
                    nearest = len(s.at - at);
                    best = &s;
                }
        }
        if (best)
            hitBy_[e.object] = static_cast<int>(best->weapon);
    }
    stepImpacts_.clear();
    // A demolition charge blasts where it landed.
    std::vector<Shell> landed;
    landed.swap(landed_);
    for (const Shell& s : landed) {
        const WeaponSpec& w = weaponSpec(s.weapon);
        if (w.blastRadius > 0)
            blast(s.at, w.blastRadius, w.blastImpulse, static_cast<int>(s.weapon));
    }
}

void Game::emitEffects(long long impactsBefore, long long retiredBefore) {
    // sparks and dust at the impacts of this frame (the newest marks)
    const auto& marks = runtime_->recentImpacts();
    const long long fresh = std::min<long long>(runtime_->counters().impacts - impactsBefore,
                                                static_cast<long long>(marks.size()));
    for (long long k = 0; k < fresh; ++k) {
        const auto& m = marks[marks.size() - 1 - static_cast<size_t>(k)];
        // sized by the hit: a 4 kg shell at 170 m/s (680 N*s) is 1, a crash's blast about 2.4
        const float strength = std::clamp(std::sqrt(static_cast<float>(m.impulse) / 680.0f), 0.4f, 3.0f);
        particles_.impactBurst(toV3(m.point), toV3(m.normal), strength, burstSeed_++);
    }
    // a puff of dust for every piece retired into a debris particle this frame (the newest particles)
    const auto& debris = runtime_->particles();
    const long long retired = std::min<long long>(runtime_->counters().piecesRetired - retiredBefore,
                                                  static_cast<long long>(debris.size()));
    for (long long k = 0; k < retired; ++k) {
        const auto& d = debris[debris.size() - 1 - static_cast<size_t>(k)];
        particles_.debrisPuff(toV3(d.position), toV3(d.velocity), static_cast<float>(d.size), burstSeed_++);
    }
}

void Game::step(const ControlInput& input, float dt, Renderer& renderer) {
    (void)renderer; // meshes follow the runtime's callbacks
    if (!runtime_)
        return;
    ++counters_.frame;
    controlVehicle(input, dt);
    if (input.weapon >= 0 && input.weapon < kWeaponCount)
        weapon_ = static_cast<Weapon>(input.weapon);
    fireCooldown_ -= dt;
    if (input.fire && vehicle_ && crashTimer_ <= 0 && (!fireWasDown_ || fireCooldown_ <= 0)) {
        fire();
        fireCooldown_ = weapon_ == Weapon::Cannon ? settings_.fireInterval : weaponSpec(weapon_).interval;
    }
    fireWasDown_ = input.fire;

    // live-tunable runtime settings
    const auto& rc = runtime_->config();
    rubble::DebrisBudget debris = rc.debris;
    debris.maxAwakeBodies = settings_.maxAwake;
    runtime_->setDebrisBudget(debris);
    rubble::ImpactPolicy impacts = rc.impacts;
    applyImpactSettings(impacts, settings_);
    runtime_->setImpactPolicy(impacts);
    rubble::SupportPolicy support = rc.support;
    support.collapseUnsupported = settings_.collapseUnsupported;
    runtime_->setSupportPolicy(support);

    const long long impactsBefore = runtime_->counters().impacts;
    const long long retiredBefore = runtime_->counters().piecesRetired;
    runtime_->setFocus({camera_.eye.x, camera_.eye.y, camera_.eye.z}); // distant tiny debris fades
    heard_ = {}; // the runtime's event lists restart with the frame
    runtime_->stepFrame(dt);
    effectsOfEvents();
    creditHits();
    checkCrash();
    emitEffects(impactsBefore, retiredBefore);
    listenForDebris();
    if (net_) { // clients follow by journal events and placements (10 Hz)
        net_->publish();
        if (counters_.frame % 6 == 0)
            net_->publishPlacements(runtime_->placements());
        net_->service(0);
    }

    for (BodyId id : runtime_->bodies())
        if (runtime_->body(id)->role == BodyRole::Projectile)
            particles_.emit(ParticleSystem::Kind::Trail, toV3(runtime_->motion(id).transform.translation),
                            V3{}, 0.18f, 0.5f, 1.0f, 0.7f, 0.3f);
    for (auto& [body, v] : visuals_)
        v.heat = std::max(0.0f, v.heat - dt * 0.6f);
    particles_.step(dt, groundTop_);
    updateCounters();
}

void Game::adoptReady(double waitMs) {
    if (!runtime_)
        return;
    if (waitMs > 0) // returns at once when nothing is in flight, and in deterministic mode
        (void)runtime_->world().waitForResult(std::chrono::steady_clock::now() +
                                              std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                  std::chrono::duration<double, std::milli>(waitMs)));
    const long long impacts = runtime_->counters().impacts;
    const long long retiredBefore = runtime_->counters().piecesRetired;
    if (runtime_->adoptReady().piecesRetired > 0)
        emitEffects(impacts, retiredBefore); // dust for pieces retired while adopting (no new impacts)
    effectsOfEvents();
    updateCounters();
}

void Game::updateCounters() {
    // latencies of adopted jobs only (stale, missed and failed jobs are not impact → adopted times)
    const auto& timings = runtime_->world().timings();
    // by sequence number: the world drops its oldest records in long games, which shifts the indices
    const std::uint64_t first = runtime_->world().firstTimingRecord();
    for (nextTiming_ = std::max(nextTiming_, first); nextTiming_ < first + timings.size(); ++nextTiming_) {
        const rubble::TimingRecord& r = timings[static_cast<std::size_t>(nextTiming_ - first)];
        if (!r.stale && !r.missed && !r.failed) {
            latencies_.push_back(r.totalMs);
            visible_.adopted(r.object, r.frame, r.totalMs, VisibleLatency::Clock::now());
        }
    }
    const auto& c = runtime_->counters();
    counters_.impacts = static_cast<int>(c.projectileHits);
    counters_.submitted = static_cast<int>(c.impacts);
    counters_.fractures = static_cast<int>(c.fractures);
    counters_.collisionsOverBudget = static_cast<int>(c.collisionsOverBudget);
    counters_.piecesCreated = static_cast<int>(c.piecesCreated);
    counters_.retired = static_cast<int>(c.piecesRetired);
    counters_.retiredBy = {static_cast<int>(c.retired.dust), static_cast<int>(c.retired.awake),
                           static_cast<int>(c.retired.triangles), static_cast<int>(c.retired.faded),
                           static_cast<int>(c.retired.fellOut)};
    counters_.collapsed = static_cast<int>(c.piecesCollapsed);
    counters_.bondsBroken = static_cast<int>(c.bondsBroken);
    counters_.bodies = static_cast<int>(runtime_->bodyCount());
    counters_.pieces = runtime_->livePieces();
    counters_.awake = runtime_->awakeDebris();
    counters_.frozen = runtime_->frozenDebris();
    counters_.light = runtime_->lightDebris();
    counters_.jobs = runtime_->world().jobsInFlight();
}

void Game::draw(Renderer& renderer, float dt) {
    if (!runtime_)
        return;
    renderer.shadows = settings_.shadows;
    for (BodyId id : runtime_->bodies()) {
        const BodyRecord* b = runtime_->body(id);
        const btRigidBody* rb = binding_->rigid(id);
        if (b->role == BodyRole::Projectile) {
            Particle p;
            p.pos = toV3(rb->getCenterOfMassPosition());
            p.size = 1.4f;
            p.r = 1.0f;
            p.g = 0.85f;
            p.b = 0.45f;
            renderer.addParticle(p, true);
            continue;
        }
        auto it = visuals_.find(id);
        if (it == visuals_.end() || it->second.mesh < 0 || (id == vehicle_ && crashTimer_ > 0))
            continue;
        M4 m;
        // render meshes are in object coordinates; the body sits at the centre of mass
        (rb->getWorldTransform() * rubble::bullet::toBt(b->objectToBody).inverse()).getOpenGLMatrix(m.m);
        renderer.drawMesh(it->second.mesh, m, it->second.heat);
    }
    if (vehicle_ && crashTimer_ <= 0) {
        // Engine glow at the tail.
        const btTransform& t = binding_->rigid(vehicle_)->getWorldTransform();
        Particle p;
        p.pos = toV3(t * btVector3(0, 0, noseOffset_ - 2.2f));
        p.size = 1.1f + 0.02f * speed_;
        p.r = 0.5f;
        p.g = 0.75f;
        p.b = 1.0f;
        p.a = 0.9f;
        renderer.addParticle(p, true);
    }
    // retired pieces still flying: small dark chunks
    for (const auto& d : runtime_->particles()) {
        Particle p;
        p.pos = toV3(d.position);
        p.size = std::clamp(static_cast<float>(d.size), 0.05f, 1.5f);
        p.r = p.g = p.b = 0.45f;
        p.a = std::min(1.0f, static_cast<float>(d.lifetime));
        renderer.addParticle(p, false);
    }
    particles_.draw(renderer);

    if (settings_.debugShapes || settings_.debugAabbs || settings_.debugImpacts) {
        rubble::bullet::DebugDrawOptions o;
        o.shapes = settings_.debugShapes;
        o.aabbs = settings_.debugAabbs;
        o.impacts = settings_.debugImpacts;
        o.impactCrossSize = 1.5;
        for (const auto& l : binding_->debugDraw(*runtime_, o).lines)
            renderer.addLine(toV3(l.from), toV3(l.to), static_cast<float>((l.rgba >> 24) & 0xFF) / 255.0f,
                             static_cast<float>((l.rgba >> 16) & 0xFF) / 255.0f,
                             static_cast<float>((l.rgba >> 8) & 0xFF) / 255.0f);
    }

    if (settings_.debugBonds) // each bond: a cross in its interface, coloured by stress / limit
        for (const rubble::StructureBond& b : runtime_->structureBonds()) {
            const float u = static_cast<float>(std::clamp(b.utilisation, 0.0, 1.0));
            const float r = std::min(1.0f, 2 * u), g = std::min(1.0f, 2 - 2 * u);
            const rubble::Vec3 t = std::abs(b.normal.y) < 0.9 ? rubble::Vec3{0, 1, 0} : rubble::Vec3{1, 0, 0};
            const double half = 0.5 * std::sqrt(b.area);
            const rubble::Vec3 e1 = rubble::normalized(rubble::cross(b.normal, t)) * half;
            const rubble::Vec3 e2 = rubble::normalized(rubble::cross(b.normal, e1)) * half;
            renderer.addLine(toV3(b.centroid - e1), toV3(b.centroid + e1), r, g, 0.1f);
            renderer.addLine(toV3(b.centroid - e2), toV3(b.centroid + e2), r, g, 0.1f);
        }

    V3 pos, fwd, up;
    vehicleFrame(pos, fwd, up);
    camera_.update(pos, fwd, up, dt);
    camera_.eye.y = std::max(camera_.eye.y, groundTop_ + 1.5f);
    if (settings_.showcase) {
        camera_.eye = showcaseEye_;
        camera_.target = showcaseAt_;
    }
}

std::vector<double> Game::takeNewLatencies() {
    std::vector<double> out(latencies_.begin() + static_cast<long>(latencyCursor_), latencies_.end());
    latencyCursor_ = latencies_.size();
    return out;
}

void Game::notePlacedDynamic() {
    placedDynamic_.clear();
    for (BodyId id : runtime_->bodies()) {
        const BodyRecord* b = runtime_->body(id);
        if (b->role == BodyRole::Object && b->motion == rubble::BodyMotionState::Dynamic)
            placedDynamic_[id] = runtime_->motion(id).transform.translation;
    }
}

std::vector<V3>
Game::centresWhere(const std::function<bool(BodyId, const BodyRecord&, const rubble::Vec3&)>& keep) const {
    std::vector<V3> out;
    if (!runtime_)
        return out;
    for (BodyId id : runtime_->bodies()) {
        const rubble::Vec3 c = runtime_->motion(id).transform.translation;
        if (keep(id, *runtime_->body(id), c))
            out.push_back(toV3(c));
    }
    return out;
}

std::vector<V3> Game::targets() const {
    return centresWhere([this](BodyId id, const BodyRecord& b, const rubble::Vec3& c) {
        const auto placed = placedDynamic_.find(id);
        const bool standingDynamic =
            placed != placedDynamic_.end() && rubble::length(c - placed->second) < 1.0;
        return standingDynamic || (b.motion == rubble::BodyMotionState::Static &&
                                   (b.role == BodyRole::Object ||
                                    (b.role == BodyRole::Piece && b.volume > 150 && c.y > groundTop_ + 15)));
    });
}

std::vector<V3> Game::shellTargets() const {
    return centresWhere([this](BodyId, const BodyRecord& b, const rubble::Vec3& c) {
        return b.role == BodyRole::Object ||
               (b.role == BodyRole::Piece && b.volume >= 1.0 && c.y > groundTop_);
    });
}

void Game::writeTimings(const std::string& path) const {
    if (runtime_)
        (void)runtime_->world().writeTimingsCsv(path);
}

bool Game::writeJournal(const std::string& path, const std::string& scene, std::string& message) const {
    if (!runtime_) {
        message = "no scene loaded";
        return false;
    }
    const rubble::JournalFile journal{rubble::journalHeaderOf(worldConfig_, scene), journal_};
    if (rubble::Status s = rubble::writeJournal(path, journal); !s) {
        message = s.message();
        return false;
    }
    message = std::to_string(journal_.size()) + " events, " +
              std::to_string(rubble::encodeJournal(journal).size()) + " bytes";
    return true;
}

std::uint64_t Game::finishRecording() {
    if (!runtime_)
        return 0;
    for (int i = 0; i < 600 && runtime_->world().jobsInFlight() > 0; ++i)
        runtime_->stepFrame();
    return runtime_->world().geometryHash();
}

bool Game::replayJournal(const std::string& path, std::uint64_t& hash, std::string& message) {
    if (!runtime_) {
        message = "no scene loaded";
        return false;
    }
    rubble::Result<rubble::JournalFile> journal = rubble::readJournal(path);
    if (!journal) {
        message = journal.error().message;
        return false;
    }
    if (rubble::Status s = rubble::checkJournalHeader(journal->header, worldConfig_); !s) {
        message = s.message() + " (replay with the recording's options, e.g. --deterministic)";
        return false;
    }
    // The replay runs on a copy of the loaded world: the runtime's own changes only as the game plays.
    rubble::DestructionWorld replayed(worldConfig_);
    if (rubble::Status s = rubble::restoreState(replayed, rubble::captureState(runtime_->world())); !s) {
        message = s.message();
        return false;
    }
    rubble::JournalPlayer player(replayed);
    for (const rubble::JournalEvent& e : journal->events)
        if (rubble::Status s = player.receive(e); !s) {
            message = s.message();
            return false;
        }
    if (rubble::Status s = player.drain(); !s) {
        message = s.message();
        return false;
    }
    hash = replayed.geometryHash();
    message = std::to_string(journal->events.size()) + " events";
    return true;
}

bool Game::host(std::uint16_t port, std::string& message) {
    if (!runtime_) {
        message = "no scene loaded";
        return false;
    }
    auto server = rubble::net::NetHost::listen(*runtime_, worldConfig_, "127.0.0.1", port);
    if (!server) {
        message = server.error().message;
        return false;
    }
    net_ = std::move(*server);
    net_->setPlacementSource([this] { return runtime_->placements(); });
    // One journal sink: the recording and the clients both get every event.
    runtime_->setJournalSink([this](const rubble::JournalEvent& e) { journaled(e); });
    message = "127.0.0.1:" + std::to_string(net_->port());
    return true;
}

bool Game::waitForClient(double timeoutSeconds) {
    const auto start = std::chrono::steady_clock::now();
    while (net_ && net_->stats().joins == 0) {
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeoutSeconds)
            return false;
        net_->service(10);
    }
    return net_ != nullptr;
}

void Game::finishHosting() {
    if (net_)
        net_->finish(5000);
}

bool Game::loadSnapshot(const std::string& path, Renderer& renderer, std::string& message) {
    if (!runtime_) {
        message = "no scene loaded";
        return false;
    }
    rubble::Result<rubble::Snapshot> snapshot = rubble::loadSnapshot(path);
    if (!snapshot) {
        message = snapshot.error().message;
        return false;
    }
    const std::size_t objects = snapshot->world.objects.size();
    if (rubble::Status s = rubble::restoreSnapshot(*runtime_, std::move(*snapshot)); !s) {
        message = s.message();
        return false;
    }
    // The old bodies' visuals went with them (onRemoved); the new ones keep the looks of their objects.
    for (BodyId id : runtime_->bodies()) {
        const rubble::BodyRecord* b = runtime_->body(id);
        if (!b->hasObject || visuals_.count(id))
            continue;
        const auto look = looks_.find(b->object);
        addVisual(id, runtime_->world().object(b->object)->mesh, look == looks_.end() ? Look{} : look->second,
                  0.0f, renderer);
    }
    notePlacedDynamic();
    message = std::to_string(objects) + " objects";
    return true;
}

bool Game::saveSnapshot(const std::string& path, std::string& message) const {
    if (!runtime_) {
        message = "no scene loaded";
        return false;
    }
    const rubble::Snapshot snapshot = rubble::takeSnapshot(*runtime_);
    if (rubble::Status s = rubble::saveSnapshot(path, snapshot); !s) {
        message = s.message();
        return false;
    }
    message = std::to_string(snapshot.world.objects.size()) + " objects";
    return true;
}

} // namespace demo
