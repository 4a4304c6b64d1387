#pragma once
/// \file Game.hpp
/// The game: a world.cfg scene loaded into Rubble's engine-neutral DestructionRuntime on the Bullet binding,
/// the flying vehicle with a stabilising assist, projectiles from its nose, and the renderer's meshes kept in
/// step with the runtime's bodies.

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "ChaseCamera.hpp"
#include "Math.hpp"
#include "ParticleSystem.hpp"
#include "PriorityJobs.hpp"
#include "Renderer.hpp"
#include "Sound.hpp"
#include "VisibleLatency.hpp"
#include "Weapons.hpp"
#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/enet/NetHost.hpp"
#include "rubble/rubble.hpp"

namespace demo {

/// Control input for one step; axes in [-1, 1].
struct ControlInput {
    float pitch = 0;    ///< +1 = nose down (W), -1 = nose up (S)
    float roll = 0;     ///< +1 = counter-clockwise (A), -1 = clockwise (D)
    float yaw = 0;      ///< +1 = left (Q), -1 = right (E)
    float throttle = 0; ///< +1 = speed up (Z), -1 = slow down (X)
    bool fire = false;  ///< Space held
    int weapon = -1;    ///< 0..2: switch to that weapon (keys 1-3); -1 keeps the current one
};

/// Tunables edited from the ImGui panel.
struct GameSettings {
    rubble::FractureParams fracture; ///< applied to objects on (re)start
    double impulseThreshold = 50;    ///< impacts below this impulse do not fracture
    double collisionImpulse = 2500;  ///< non-projectile contacts above this impulse fracture too
    double blastCutVolume = rubble::ImpactPolicy{}.blastCutVolume; ///< blasts throw moving bodies below this
    double collisionFractureRate = 0; ///< non-projectile contacts start at most this many fractures a second
    int blastMaxCuts = 4;             ///< a blast cuts at most this many moving bodies, nearest first
    int workers = -1;                 ///< fracture worker threads (-1 automatic), applied on restart
    int workerNice = 0;               ///< niceness of the fracture workers (0: unchanged), applied on restart
    bool deterministic = false;       ///< adopt results a fixed number of frames after the impact
    float timeScale = 1;              ///< slow motion factor
    float projectileSpeed = 170;      ///< m/s
    float projectileMass = 4;         ///< kg
    float fireInterval = 0.14f;       ///< s between shots while Space is held
    float minPieceVolume = 0.02f;     ///< m^3: smaller pieces become debris particles (applied on restart)
    int maxAwake = 400;               ///< awake debris budget: beyond it the smallest retire to particles
    double lightPerAwake =
        4; ///< moving pieces over the budget collide with static bodies only, up to this many
           ///< per budgeted awake body, before any retires (DebrisBudget::lightPerAwake)
    bool collapseUnsupported = true; ///< static pieces with nothing static under them fall (live)
    bool debugShapes = false;        ///< draw collision shapes
    bool debugAabbs = false;         ///< draw AABBs
    bool debugImpacts = false;       ///< draw impact points
    bool structure = true;           ///< stress solver: overstressed bonds break (applied on restart)
    bool roughCuts = true;           ///< cuts rough by material preset (SceneLoadOptions::materialRoughness)
    bool debugBonds = false;         ///< draw the structure's bonds, green (idle) to red (breaking)
    bool shadows = true;             ///< shadow mapping
    bool autoLevel = true;           ///< wings level themselves when no roll key is held (L toggles)
    bool showcase = false; ///< the camera frames the scene's objects from a fixed point (screenshots)
};

/// Counters shown in the panel and printed by --stats.
struct GameCounters {
    std::uint64_t frame = 0;        ///< simulation frames (frozen while paused)
    int shots = 0;                  ///< projectiles fired
    int impacts = 0;                ///< projectile hits (on objects or the ground)
    int submitted = 0;              ///< impacts accepted by the DestructionWorld
    int fractures = 0;              ///< fracture results adopted
    int piecesCreated = 0;          ///< piece bodies created
    int retired = 0;                ///< pieces turned into particles
    std::array<int, 5> retiredBy{}; ///< the same by reason: dust, awake budget, triangles, faded, fell out
    int collapsed = 0;              ///< static bodies that lost their support and fell
    int bondsBroken = 0;            ///< structure bonds broken (stress solver on)
    int bodies = 0;                 ///< rigid bodies in the physics world
    int pieces = 0;                 ///< live piece bodies
    int awake = 0;                  ///< dynamic debris bodies (pieces and objects)
    int frozen = 0;                 ///< debris bodies frozen at rest
    int light = 0;                  ///< awake debris over the budget, colliding with static bodies only
    int jobs = 0;                   ///< fracture jobs queued or running
    int warnings = 0;               ///< scene warnings
    int crashes = 0;                ///< the jet hit the ground or an object
    int blastThrown = 0;            ///< moving pieces blasts threw instead of cutting
    int collisionsOverBudget = 0;   ///< collision impacts over GameSettings::collisionFractureRate, dropped
    int respawns = 0;               ///< the jet came back (2 s after a crash, or R)
    int turnBacks = 0;              ///< times the world bounds started turning the jet back
    std::array<int, kWeaponCount> weaponShots{};     ///< shots fired, by weapon
    std::array<int, kWeaponCount> weaponFractures{}; ///< fractures adopted whose impact came from the weapon
    std::array<int, kSoundKinds> sounds{};           ///< sounds made, by SoundKind
};

/// The game world.
class Game {
public:
    Game();
    ~Game();
    Game(const Game&) = delete;
    Game& operator=(const Game&) = delete;

    /// Builds the world from a scene; warnings (missing files, stand-ins) are appended.
    bool load(const rubble::SceneConfig& scene, Renderer& renderer, const GameSettings& settings,
              std::vector<std::string>& warnings, std::string& error);
    /// Tears everything down (renderer meshes included).
    void clear(Renderer& renderer);

    /// One fixed step of dt seconds (already scaled by slow motion).
    void step(const ControlInput& input, float dt, Renderer& renderer);
    /// Adopts the fracture results that are ready now (call after the steps, right before drawing, so that
    /// pieces appear in the frame in which their job finished), first waiting up to waitMs for a job in
    /// flight to finish; does nothing in deterministic mode.
    void adoptReady(double waitMs = 0);
    /// Queues the frame's draws (meshes, particles, debug lines) and updates the camera.
    void draw(Renderer& renderer, float dt);

    /// Counters.
    const GameCounters& counters() const { return counters_; }
    /// The runtime (null before a scene is loaded).
    const rubble::DestructionRuntime* runtime() const { return runtime_.get(); }
    /// Settings (mutable: panel edits them; some apply on restart).
    GameSettings& settings() { return settings_; }
    /// Camera.
    const ChaseCamera& camera() const { return camera_; }
    /// Vehicle position, forward and up (world).
    void vehicleFrame(V3& pos, V3& forward, V3& up) const;
    /// The weapon fired by Space.
    Weapon weapon() const { return weapon_; }
    /// Selects the weapon (keys 1-3).
    void setWeapon(Weapon w) { weapon_ = w; }
    /// Velocity (world, m/s) of a shell the current weapon would fire now: the jet's plus the muzzle speed.
    V3 shotVelocity() const;
    /// Current vehicle speed setting (m/s).
    float speed() const { return speed_; }
    /// Puts the jet back at its start, flying (R; also 2 s after a crash).
    void respawn();
    /// True while the jet is wrecked (between a crash and the respawn).
    bool crashed() const { return crashTimer_ > 0; }
    /// True while the world bounds steer the jet back inside.
    bool turningBack() const { return turningBack_; }
    /// Slowest speed the jet flies at (m/s): X cannot stop it in the air.
    static constexpr float kStallSpeed = 15.0f;
    /// Crash or blast: impacts on every destructible body within radius of point, sparks and dust; the
    /// fractures they cause count for `by` (a weapon index, or -1 for a crash).
    void blast(const V3& point, float radius, float impulse, int by = -1);
    /// A demolition charge's blast on the next standing target (round robin over targets()), for --demolish;
    /// false when nothing stands.
    bool blastNextTarget();
    /// A cannon shell at the next of the scene's objects wherever they lie (round robin over shellTargets()),
    /// fired from 40 m off on the side of `from` (the camera), for --fire-rate; false when none is left.
    bool shootNextTarget(const V3& from);
    /// One impact at a world point on the objects whose bounds reach it (no sparks); false when none took it.
    bool hitAt(const V3& point, float impulse);
    /// Places the showcase camera (GameSettings::showcase) at eye, looking at target.
    void setShowcaseView(const V3& eye, const V3& target) {
        showcaseEye_ = eye;
        showcaseAt_ = target;
    }
    /// Sounds (impacts, breaks, debris hitting the ground) made since the last call.
    std::vector<SoundEvent> takeSounds();
    /// Latencies (impact → adopted, ms) of results adopted since the last call.
    std::vector<double> takeNewLatencies();
    /// All adopted latencies so far (ms).
    const std::vector<double>& latencies() const { return latencies_; }
    /// A frame was presented now: fractures adopted before it are visible (impact → visible times).
    void presented() { visible_.presented(VisibleLatency::Clock::now()); }
    /// Impact → visible times of the fractures shown so far.
    const VisibleLatency& visibleLatency() const { return visible_; }
    /// The fracture workers (null before a scene is loaded).
    const PriorityJobs* jobs() const { return jobs_.get(); }
    /// Centres of destructible objects still standing (for the autopilot).
    std::vector<V3> targets() const;
    /// Centres of the scene's objects, standing or not, and of pieces of 1 m³ or more (--fire-rate).
    std::vector<V3> shellTargets() const;
    /// Height of the ground surface.
    float groundY() const { return groundTop_; }
    /// True: fracture runs on Rubble's DestructionWorld runtime (kept for the panel and the run report).
    static bool fractureAvailable() { return true; }
    /// Writes the runtime's timing records as CSV.
    void writeTimings(const std::string& path) const;
    /// Writes the journal of everything destroyed since load() (a bug report: replays to the same geometry on
    /// a world built from the same scene, docs/journal.md); false with a message when it cannot.
    bool writeJournal(const std::string& path, const std::string& scene, std::string& message) const;
    /// Steps until no fracture job is in flight (so that a replay of the journal ends in the same state) and
    /// returns the world's geometry hash.
    std::uint64_t finishRecording();
    /// Replays a journal file on the freshly loaded scene (the world steps alone, no bodies are made) until
    /// no job is in flight; the geometry hash then equals the recording's finishRecording(). False with a
    /// message when the file cannot be read or does not belong to this scene and these settings.
    bool replayJournal(const std::string& path, std::uint64_t& hash, std::string& message);
    /// Hosts loopback multiplayer on 127.0.0.1:port (docs/netplay.md): clients get a snapshot, then the
    /// journal and the bodies' placements every step. Needs deterministic settings; false with a message.
    bool host(std::uint16_t port, std::string& message);
    /// Serves the network without stepping until a client has joined; false after timeoutSeconds.
    bool waitForClient(double timeoutSeconds);
    /// Waits (at most 5 s) until every client confirmed the last sync; no-op when not hosting.
    void finishHosting();
    /// The host's totals, or null when not hosting.
    const rubble::net::HostStats* hostStats() const { return net_ ? &net_->stats() : nullptr; }
    /// The world's geometry hash.
    std::uint64_t geometryHash() const { return runtime_ ? runtime_->world().geometryHash() : 0; }
    /// Loads a snapshot saved by saveSnapshot (F9): the world and its objects' bodies are replaced; false
    /// with a message (the game unchanged) when the file is damaged or belongs to other settings.
    bool loadSnapshot(const std::string& path, Renderer& renderer, std::string& message);
    /// Saves a snapshot of the destroyed world and its bodies (F5); false with a message when it cannot.
    bool saveSnapshot(const std::string& path, std::string& message) const;

private:
    /// Centres of the bodies `keep` accepts (body id, record, centre).
    std::vector<V3> centresWhere(const std::function<bool(rubble::BodyId, const rubble::BodyRecord&,
                                                          const rubble::Vec3&)>& keep) const;
    /// How a body with a render mesh looks.
    struct Visual {
        int mesh = -1;    ///< renderer mesh (object coordinates)
        float heat = 0;   ///< glow of fresh cut faces
        V3 tint{1, 1, 1}; ///< colour multiplier
    };
    /// Texture and tint an object passes on to its pieces.
    struct Look {
        int texture = 0;               ///< renderer texture
        V3 tint{1, 1, 1};              ///< colour multiplier
        int interior = -1;             ///< cut faces' texture, by the object's material (-1: the default)
        Timbre timbre = Timbre::Stone; ///< how the object's material sounds
    };
    void fire();
    void launch(const btVector3& from, const btVector3& velocity, Weapon weapon);
    void journaled(const rubble::JournalEvent& e);
    void creditHits();
    void onAdopted(const rubble::FractureOutcome& outcome, Renderer& renderer);
    /// Records where the objects that are dynamic from the start stand (targets until they move).
    void notePlacedDynamic();
    void addVisual(rubble::BodyId body, const rubble::Mesh& mesh, const Look& look, float heat,
                   Renderer& renderer);
    void controlVehicle(const ControlInput& input, float dt);
    void checkCrash();
    void emitEffects(long long impactsBefore, long long retiredBefore);
    void listenForDebris();
    void effectsOfEvents();
    void sound(const SoundEvent& e);
    void updateCounters();

    GameSettings settings_;
    GameCounters counters_;
    ChaseCamera camera_;
    ParticleSystem particles_;
    // destroyed in reverse order: the runtime before the binding before the physics world before the workers
    std::unique_ptr<PriorityJobs> jobs_;
    std::unique_ptr<rubble::bullet::PhysicsWorld> physics_;
    std::unique_ptr<rubble::bullet::BulletBinding> binding_;
    std::unique_ptr<rubble::DestructionRuntime> runtime_;
    rubble::DestructionWorld::Config worldConfig_;
    std::unique_ptr<rubble::net::NetHost> net_; // hosting loopback multiplayer (before the runtime goes)
    std::vector<rubble::JournalEvent> journal_; // every accepted impact and removal since load()
    std::unordered_map<rubble::BodyId, Visual> visuals_;
    std::map<rubble::ObjectId, Look> looks_;
    std::unordered_map<rubble::BodyId, rubble::Vec3>
        placedDynamic_; // objects dynamic at load: where they stood
    rubble::BodyId vehicle_ = 0;
    float speed_ = 30;
    float fireCooldown_ = 0;
    bool fireWasDown_ = false;
    float groundTop_ = -10;
    std::vector<double> latencies_;
    size_t latencyCursor_ = 0;
    VisibleLatency visible_;       // adopted fractures until the frame that draws them is presented
    std::uint64_t nextTiming_ = 0; // sequence number of the next timing record to read
    std::uint32_t burstSeed_ = 1;
    float noseOffset_ = 3;
    V3 spawnPos_{0, 20, 0};    // where the jet starts and respawns
    float crashTimer_ = 0;     // s until the respawn (0: flying)
    bool turningBack_ = false; // the bounds steer this step
    bool hover_ = false;       // a mass-0 vehicle (thesis: static) hovers and has no stall floor
    float boundsMinX_ = -500, boundsMaxX_ = 500, boundsMinZ_ = -500, boundsMaxZ_ = 500; // ground's extent
    rubble::BodyId groundBody_ = 0;
    Weapon weapon_ = Weapon::Cannon;
    V3 showcaseEye_{}, showcaseAt_{}; // the showcase camera, framing the objects as loaded
    /// A shell in flight, and where a spent one was removed.
    struct Shell {
        Weapon weapon = Weapon::Cannon;
        V3 at{};
        bool spent = false;
    };
    std::unordered_map<rubble::BodyId, Shell> shells_; // shells in flight
    std::vector<Shell> landed_;                        // shells that hit something this step
    std::vector<rubble::JournalEvent> stepImpacts_;    // impacts journaled this step, credited after it
    int blastBy_ = -1;                                 // weapon whose blast is submitting impacts
    std::size_t nextTarget_ = 0;                       // --demolish: the target blasted next
    std::size_t nextShot_ = 0;                         // --fire-rate: the target shot next
    std::map<rubble::ObjectId, int> hitBy_;            // object -> weapon whose impact will fracture it
    std::vector<SoundEvent> sounds_;                   // made since the last takeSounds()
    std::unordered_map<rubble::BodyId, std::uint64_t> lastKnock_; // body -> frame it last hit the ground
    struct EventsHeard { // of the runtime's event lists of this frame, those already sounded and shown
        std::size_t pieces = 0, breaks = 0, collapses = 0;
    };
    EventsHeard heard_;
};

} // namespace demo
