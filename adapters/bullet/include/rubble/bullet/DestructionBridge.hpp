#pragma once
/// \file DestructionBridge.hpp
/// Connects a PhysicsWorld (Bullet) with a DestructionWorld (Rubble): owns the bodies of objects and pieces,
/// turns contacts into impacts, adopts fracture outcomes as piece bodies, and keeps the live set bounded by
/// retiring small or surplus pieces into debris particles (their volume stays counted).

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rubble/DestructionWorld.hpp"
#include "rubble/bullet/Body.hpp"
#include "rubble/bullet/DebrisParticle.hpp"
#include "rubble/bullet/DebugDraw.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"

namespace rubble::bullet {

/// What one frame did.
struct FrameStats {
    int substeps = 0;         ///< internal physics steps
    int impactsSubmitted = 0; ///< impacts accepted by the DestructionWorld
    int projectileHits = 0;   ///< projectiles that hit something this frame
    int fractures = 0;        ///< outcomes adopted
    int piecesCreated = 0;    ///< piece bodies created
    int piecesRetired = 0;    ///< pieces turned into debris particles (including ones never given a body)
    int piecesCollapsed = 0;  ///< static objects or pieces that lost their support and became dynamic
    int supportQueries = 0;   ///< contact pair tests run for support checks
    double supportMs = 0;     ///< of adoptMs: support checks (neighbour queries, searches, collapses)
    double physicsMs = 0;     ///< physics step incl. contact gathering
    double adoptMs = 0;       ///< submit + collect + adoption + retiring
};

/// Totals since construction.
struct BridgeCounters {
    std::uint64_t frames = 0;      ///< frames stepped
    long long impacts = 0;         ///< impacts accepted by the DestructionWorld
    long long projectileHits = 0;  ///< projectile hits on anything
    long long fractures = 0;       ///< outcomes adopted
    long long piecesCreated = 0;   ///< piece bodies created
    long long piecesRetired = 0;   ///< pieces retired into particles
    long long piecesCollapsed = 0; ///< static objects or pieces that lost their support and became dynamic
    long long supportQueries = 0;  ///< contact pair tests run for support checks
    long long staleOutcomes = 0;   ///< outcomes whose parent had no body
};

/// A recent impact, for debug drawing.
struct ImpactMark {
    Vec3 point;         ///< world position
    Vec3 normal;        ///< world normal (out of the object hit)
    double impulse = 0; ///< impulse submitted
};

/// The Bullet side of destruction. Call everything from the main thread. Destroy it before the PhysicsWorld
/// and the DestructionWorld it refers to.
class DestructionBridge {
public:
    /// Tunables.
    struct Config {
        double collisionImpulseThreshold = 2500; ///< non-projectile contacts fracture only above this total
                                                 ///< impulse per contact pair and step (and the object's own
                                                 ///< threshold)
        double minApproachSpeed = 2.0; ///< non-projectile contacts also need this approach speed (m/s)
        int graceFrames = 30;          ///< new pieces ignore non-projectile contacts for this many frames
        double minPieceVolume = 1e-3;  ///< pieces below this volume (m³) become debris particles at once
        double minFractureVolume = 0;  ///< impacts on objects below this volume are ignored
        int maxLivePieces = 250;       ///< beyond this many piece bodies the smallest retire to particles
                                       ///< (250 keeps the physics step p99 under 8 ms on the seed world)
        std::size_t maxLivePieceTriangles =
            200000;                  ///< beyond this many triangles in dynamic piece bodies the
                                     ///< smallest retire to particles (bounds their memory)
        double debrisLifetime = 3.0; ///< seconds a debris particle is drawn
        double debrisKick = 0.5;     ///< share of a hit's impulse that throws the debris of a *static* object
                                     ///< outward (along the surface normal, spread away from the impact);
                                     ///< dynamic objects already took the impulse from the physics engine
        double maxDebrisKickSpeed = 12; ///< upper bound of that outward speed (m/s)
        double singleHullVolume = 0.25; ///< pieces below this volume (m³) collide as one convex hull of their
                                        ///< parts (cheaper contacts for small debris)
        double collisionMargin = 0.02;   ///< convex hull margin (hulls are eroded by it)
        double linearSleep = 0.8;        ///< sleeping threshold (m/s)
        double angularSleep = 1.0;       ///< sleeping threshold (rad/s)
        double killBelowY = -500;        ///< pieces falling below this height retire
        bool keepStaticRemainder = true; ///< false: every piece of a static object becomes dynamic
        bool collapseUnsupported = true; ///< a static object's remainder pieces stay static only while a
                                         ///< chain of touching static bodies links them to the ground, static
                                         ///< scenery or an anchor; others (and whatever they alone held up)
                                         ///< fall. Off: the largest piece stays static, the rest falls.
                                         ///< A static object that touched no supported static body (a
                                         ///< floating platform) keeps its largest remainder piece static.
        double supportTolerance = 0.02;  ///< gap (m) between static bodies that still counts as touching
        int maxSupportVisits = 64;       ///< static bodies one support search visits; a larger structure
                                         ///< is assumed supported
        int maxSupportSearches = 64;     ///< support searches per frame; the rest wait for the next frame
        double projectileLifetime = 6;   ///< seconds before a projectile is removed
        double spentProjectileLifetime = 0.5; ///< seconds a projectile lives after its hit
        int maxImpactMarks = 64;              ///< recent impacts kept for debug drawing
    };

    /// A bridge between the two worlds with the given tunables.
    DestructionBridge(PhysicsWorld& physics, DestructionWorld& destruction, Config config);
    /// Removes and frees every body it created.
    ~DestructionBridge();
    DestructionBridge(const DestructionBridge&) = delete;
    DestructionBridge& operator=(const DestructionBridge&) = delete;

    /// The DestructionWorld it feeds.
    DestructionWorld& destruction() { return destruction_; }
    /// The PhysicsWorld it steps.
    PhysicsWorld& physics() { return physics_; }
    /// The tunables (may be changed between frames).
    Config& config() { return config_; }

    /// A static ground box centred at center with the given half extents.
    Body& addGround(const Vec3& center, const Vec3& halfExtents);
    /// A destructible (or indestructible) object: added to the DestructionWorld, then given a body whose
    /// object frame is placed at `placement` (world ← object coordinates). Static objects (isStatic) do not
    /// move but still break. Mass = desc.density · volume. Fails when the DestructionWorld refuses the mesh.
    Result<ObjectId> addObject(ObjectDesc desc, const Frame& placement, bool isStatic);
    /// An indestructible convex body (e.g. the vehicle): convex hull of points (object coordinates, placed at
    /// placement), mass 0 = static. Fails for fewer than 4 non-coplanar points.
    Result<Body*> addConvexBody(const std::vector<Vec3>& points, const Frame& placement, double mass);
    /// Fires a projectile: a sphere of the given radius and mass from `from` with `velocity`, with
    /// continuous collision detection. Its first hit on a destructible object always counts as an impact.
    Body& fireProjectile(const Vec3& from, const Vec3& velocity, double mass, double radius);
    /// Removes a body it created (a destructible object's DestructionWorld object is removed too).
    void removeBody(Body& body);

    /// One frame: physics step of dt (fixed internal steps), impacts gathered and submitted,
    /// DestructionWorld::beginFrame() and collect(), outcomes adopted, pieces retired, particles advanced.
    FrameStats stepFrame(double dt = 1.0 / 60);
    /// Adopts the results that are ready now, between frames (the adoption half of stepFrame: collect,
    /// adopt, retire excess pieces, settle support within what is left of the frame's support budget), so
    /// that pieces appear in the frame in which their job finished instead of at the next stepFrame. Does
    /// nothing when no result is ready (DestructionWorld::waitForResult with a past deadline), hence nothing
    /// in deterministic mode. Fills fractures, pieces*, support* and adoptMs of the returned stats.
    FrameStats adoptReady();

    /// The body of an object, or null.
    Body* bodyOf(ObjectId id);
    /// Every body in creation order.
    std::vector<Body*> bodies() const;
    /// Number of bodies.
    std::size_t bodyCount() const { return bodies_.size(); }
    /// Live piece bodies.
    int livePieces() const { return livePieces_; }
    /// Triangles of the meshes of the dynamic piece bodies (what Config::maxLivePieceTriangles bounds).
    std::size_t livePieceTriangles() const;
    /// Debris particles still drawn.
    const std::vector<DebrisParticle>& particles() const { return particles_; }
    /// Recent impacts (oldest first).
    const std::deque<ImpactMark>& recentImpacts() const { return marks_; }
    /// Totals.
    const BridgeCounters& counters() const { return counters_; }

    /// Volume of all object and piece bodies (m³).
    double liveVolume() const;
    /// Volume of retired pieces (m³), counted forever.
    double retiredVolume() const { return retiredVolume_; }
    /// Volume of slivers the fracture kernel dropped (m³).
    double droppedVolume() const { return droppedVolume_; }
    /// liveVolume() + retiredVolume() + droppedVolume(): constant up to the fracture's volume error.
    double totalVolume() const { return liveVolume() + retiredVolume_ + droppedVolume_; }
    /// Σ mass · velocity over dynamic bodies that carry an object (kg·m/s).
    Vec3 objectMomentum() const;
    /// Σ mass over bodies that carry an object.
    double objectMass() const;

    /// Hash of the live object set sorted by id (id, version, mesh hash, transform bits) and of the
    /// retired volume: equal runs give equal hashes.
    std::uint64_t stateHash() const;
    /// Line segments for a debug renderer.
    DebugDraw debugDraw(const DebugDrawOptions& options = {}) const;

    /// Called for every adopted outcome after its piece bodies exist (e.g. for the renderer).
    void setOnAdopted(std::function<void(const FractureOutcome&)> callback) {
        onAdopted_ = std::move(callback);
    }
    /// Called before a body is removed and freed (e.g. for the renderer).
    void setOnRemoved(std::function<void(Body&)> callback) { onRemoved_ = std::move(callback); }

private:
    struct PendingImpact {
        ObjectId object = 0;
        Impact impact;
        Vec3 worldPoint;
        Vec3 worldNormal;
    };
    Body& insert(std::unique_ptr<Body> body);
    void destroy(std::uint64_t handle, bool removeObject);
    Body* makeObjectBody(ObjectId id, const btTransform& bodyWorld, bool isStatic, BodyKind kind);
    void preTick();
    void postTick();
    void submitImpacts(FrameStats& stats);
    void adoptResults(FrameStats& stats);
    void adopt(const FractureOutcome& outcome, FrameStats& stats);
    void retire(std::uint64_t handle, FrameStats& stats);
    void retireExcess(FrameStats& stats);
    std::vector<std::uint64_t> staticNeighbours(const Body& body, FrameStats& stats);
    void queueNeighbours(const Body& body, FrameStats& stats);
    enum class Support { Supported, Unsupported, Unknown };
    Support searchSupport(std::uint64_t start, std::vector<std::uint64_t>& component, FrameStats& stats);
    void classifyStaticObjects(FrameStats& stats);
    void settleSupport(FrameStats& stats);
    void makeDynamic(std::uint64_t handle, FrameStats& stats);
    void advanceParticlesAndProjectiles(double dt);
    std::uint64_t handleOf(const Body& body) const;

    PhysicsWorld& physics_;
    DestructionWorld& destruction_;
    Config config_;
    std::map<std::uint64_t, std::unique_ptr<Body>> bodies_; // handle (creation order) → body
    std::map<ObjectId, std::uint64_t> byObject_;
    std::uint64_t nextHandle_ = 1;
    int livePieces_ = 0;
    std::vector<PendingImpact> projectileImpacts_;
    std::vector<std::uint64_t> unclassified_; // static objects whose anchor flag is not decided yet
    std::deque<std::uint64_t> supportQueue_;  // static bodies whose support must be re-checked
    int supportSearchesLeft_ = 0;             // of config_.maxSupportSearches this frame
    std::map<ObjectId, PendingImpact> collisionImpacts_;
    std::vector<DebrisParticle> particles_;
    std::deque<ImpactMark> marks_;
    BridgeCounters counters_;
    double retiredVolume_ = 0;
    double droppedVolume_ = 0;
    std::function<void(const FractureOutcome&)> onAdopted_;
    std::function<void(Body&)> onRemoved_;
};

} // namespace rubble::bullet
