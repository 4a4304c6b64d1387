#pragma once
/// \file Game.hpp
/// The game: a Bullet world built from a world.cfg scene, the flying vehicle with a stabilising assist,
/// projectiles from its nose, impacts handed to Rubble's DestructionWorld and pieces adopted back.

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "ChaseCamera.hpp"
#include "LocalFracture.hpp"
#include "Math.hpp"
#include "ParticleSystem.hpp"
#include "Renderer.hpp"
#include "rubble/Fracture.hpp"
#include "rubble/SceneConfig.hpp"

class btRigidBody;
class btCollisionShape;
class btDiscreteDynamicsWorld;
class btDefaultCollisionConfiguration;
class btCollisionDispatcher;
class btBroadphaseInterface;
class btSequentialImpulseConstraintSolver;

namespace rubble {
class DestructionWorld;
}

namespace demo {

/// Control input for one step; axes in [-1, 1].
struct ControlInput {
    float pitch = 0;    ///< +1 = nose down (W), -1 = nose up (S)
    float roll = 0;     ///< +1 = counter-clockwise (A), -1 = clockwise (D)
    float yaw = 0;      ///< +1 = left (Q), -1 = right (E)
    float throttle = 0; ///< +1 = speed up (Z), -1 = slow down (X)
    bool fire = false;  ///< Space held
};

/// Tunables edited from the ImGui panel.
struct GameSettings {
    rubble::FractureParams fracture; ///< applied to objects on (re)start
    double impulseThreshold = 50;    ///< impacts below this impulse do not fracture
    double collisionImpulse = 2500;  ///< non-projectile contacts above this impulse fracture too
    int workers = -1;                ///< fracture worker threads (-1 automatic), applied on restart
    bool deterministic = false;      ///< adopt results a fixed number of frames after the impact
    float timeScale = 1;             ///< slow motion factor
    float projectileSpeed = 170;     ///< m/s
    float projectileMass = 4;        ///< kg
    float fireInterval = 0.14f;      ///< s between shots while Space is held
    float minPieceVolume = 0.02f;    ///< m^3: smaller pieces become debris particles
    int maxPieces = 600;             ///< beyond this, the smallest old pieces retire to particles
    bool debugShapes = false;        ///< draw collision shapes
    bool debugAabbs = false;         ///< draw AABBs
    bool debugImpacts = false;       ///< draw impact points
    bool shadows = true;             ///< shadow mapping
};

/// Counters shown in the panel and printed by --stats.
struct GameCounters {
    std::uint64_t frame = 0; ///< simulation frames (frozen while paused)
    int shots = 0;           ///< projectiles fired
    int impacts = 0;         ///< projectile hits on objects
    int submitted = 0;       ///< impacts accepted by the DestructionWorld
    int fractures = 0;       ///< fracture results adopted
    int piecesCreated = 0;   ///< piece bodies created
    int retired = 0;         ///< pieces turned into particles
    int bodies = 0;          ///< rigid bodies in the physics world
    int pieces = 0;          ///< live piece bodies
    int jobs = 0;            ///< fracture jobs queued or running
    int warnings = 0;        ///< scene warnings
};

/// One recent impact for the debug overlay.
struct ImpactMark {
    V3 point;      ///< world position
    V3 normal;     ///< world normal
    float age = 0; ///< seconds since the impact
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
    /// Queues the frame's draws (meshes, particles, debug lines) and updates the camera.
    void draw(Renderer& renderer, float dt);

    /// Counters.
    const GameCounters& counters() const { return counters_; }
    /// Settings (mutable: panel edits them; some apply on restart).
    GameSettings& settings() { return settings_; }
    /// Camera.
    const ChaseCamera& camera() const { return camera_; }
    /// Vehicle position, forward and up (world).
    void vehicleFrame(V3& pos, V3& forward, V3& up) const;
    /// Current vehicle speed setting (m/s).
    float speed() const { return speed_; }
    /// Latencies (impact → adopted, ms) of results adopted since the last call.
    std::vector<double> takeNewLatencies();
    /// All adopted latencies so far (ms).
    const std::vector<double>& latencies() const { return latencies_; }
    /// Centres of destructible objects still standing (for the autopilot).
    std::vector<V3> targets() const;
    /// Height of the ground surface.
    float groundY() const { return groundTop_; }
    /// True when Rubble's fracture runtime is linked in.
    static bool fractureAvailable();
    /// Writes the runtime's timing records as CSV (no-op without the runtime).
    void writeTimings(const std::string& path) const;

private:
    struct Body;
    Body* addBody(std::unique_ptr<Body> b);
    void removeBody(Body* b, Renderer& renderer);
    void fire(Renderer& renderer);
    void processContacts(Renderer& renderer);
    void adoptFractures(Renderer& renderer);
    void retireExcessPieces(Renderer& renderer);
    void controlVehicle(const ControlInput& input, float dt);
    void spawnPiece(const Body& parent, const rubble::Mesh& mesh, const rubble::Mat3& rotation,
                    const rubble::Vec3& offset, double volume, const rubble::Vec3& inertia, double density,
                    std::uint32_t object, const std::vector<std::vector<rubble::Vec3>>& parts,
                    Renderer& renderer);

    GameSettings settings_;
    GameCounters counters_;
    ChaseCamera camera_;
    ParticleSystem particles_;
    std::unique_ptr<btDefaultCollisionConfiguration> collisionConfig_;
    std::unique_ptr<btCollisionDispatcher> dispatcher_;
    std::unique_ptr<btBroadphaseInterface> broadphase_;
    std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
    std::unique_ptr<btDiscreteDynamicsWorld> world_;
    std::shared_ptr<rubble::DestructionWorld>
        destruction_; ///< shared_ptr: no destructor reference without the runtime
    std::vector<std::unique_ptr<Body>> bodies_;
    LocalFracture local_; ///< stand-in fracture while the runtime is not linked
    std::uint32_t nextLocalId_ = 1;
    Body* vehicle_ = nullptr;
    float speed_ = 30;
    float fireCooldown_ = 0;
    bool fireWasDown_ = false;
    float groundTop_ = -10;
    float time_ = 0;
    std::deque<ImpactMark> marks_;
    std::vector<double> latencies_;
    size_t latencyCursor_ = 0;
    size_t timingCursor_ = 0;
    std::uint32_t burstSeed_ = 1;
    float noseOffset_ = 3;
    int vehicleTexture_ = 0;
};

} // namespace demo
