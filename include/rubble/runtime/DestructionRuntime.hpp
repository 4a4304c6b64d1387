#pragma once
/// \file DestructionRuntime.hpp
/// The engine-neutral runtime of a destructible world: bodies in a physics engine (through a PhysicsBinding),
/// impacts from their contacts, fracture outcomes adopted as piece bodies, structural support and collapse,
/// and a debris governor that keeps thousands of pieces affordable (freezing, particles, budgets).

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "rubble/runtime/PhysicsBinding.hpp"
#include "rubble/structure/StructureSettings.hpp"

namespace rubble {

/// What a body is in the game.
enum class BodyRole : std::uint8_t {
    Ground,     ///< a static ground box (a root of support)
    Scenery,    ///< an indestructible body that is no DestructionWorld object (e.g. a vehicle)
    Object,     ///< a destructible object added by the game or a scene
    Piece,      ///< a piece made by a fracture
    Projectile, ///< a fast small sphere whose first hit on an object always counts as an impact
};

/// How a body moves.
enum class BodyMotionState : std::uint8_t {
    Static,  ///< does not move: ground, scenery or a structural part held up by what it touches
    Dynamic, ///< simulated
    Frozen,  ///< a piece that came to rest and was made static by the debris governor; wakes when hit
};

/// The runtime's record of one body.
struct RUBBLE_API BodyRecord {
    BodyId id = 0;                                    ///< its id in the PhysicsBinding
    BodyRole role = BodyRole::Scenery;                ///< role
    BodyMotionState motion = BodyMotionState::Static; ///< static, dynamic or frozen
    bool hasObject = false;                           ///< `object` names a DestructionWorld object
    ObjectId object = 0;                              ///< the object (when hasObject)
    Frame objectToBody;          ///< body → object coordinates: p_object = rotation · p_body + translation
    double volume = 0;           ///< solid volume (m³)
    double mass = 0;             ///< mass when dynamic (kg)
    Vec3 inertia;                ///< principal moments when dynamic (kg·m²)
    std::size_t triangles = 0;   ///< triangles of its mesh
    double radius = 0;           ///< bounding sphere radius about the body origin (projectile: its radius)
    std::uint64_t bornFrame = 0; ///< frame it was created in
    bool anchor = false;     ///< static and holds itself up (a floating platform, or the kept piece of one)
    bool structural = false; ///< static and part of the support graph
    bool spent = false;      ///< projectile: its one hit has been counted
    double age = 0;          ///< seconds since creation
    double spentAge = 0;     ///< projectile: seconds since its hit

    /// Dynamic or frozen piece or object: debris the governor manages.
    bool isDebris() const {
        return (role == BodyRole::Piece || role == BodyRole::Object) && motion != BodyMotionState::Static;
    }
};

/// What a blast did (DestructionRuntime::blast).
struct RUBBLE_API BlastOutcome {
    int impacts = 0; ///< impacts accepted: the bodies it cuts
    int thrown = 0;  ///< moving bodies it threw instead (below blastCutVolume, or past blastMaxCuts)
};

/// When contacts become impacts (ImpactCollector).
struct RUBBLE_API ImpactPolicy {
    double collisionImpulseThreshold = 2500; ///< non-projectile contacts fracture above this (N·s a step)
    double collisionFracturesPerSecond = 0;  ///< they start at most this many fractures a second (0: no cap)
    double minApproachSpeed = 2.0;           ///< non-projectile contacts also need this approach speed (m/s)
    int graceFrames = 30;         ///< new pieces ignore non-projectile contacts for this many frames
    double minFractureVolume = 0; ///< impacts on bodies below this volume (m³) are ignored
    double blastCutVolume = 0.25; ///< a blast throws, not cuts, moving bodies below this volume (m³)
    double blastThrowSpeed = 8;   ///< most speed (m/s) a blast gives a body it throws, at its centre
    int blastMaxCuts = 0;         ///< a blast cuts at most this many moving bodies, nearest first (0: any)
    double maxContactDistance = 0.05; ///< contacts farther apart than this (m) are not hits
    int maxImpactMarks = 64;          ///< recent impacts kept for debug drawing
};

/// How fracture outcomes become bodies (PieceAdopter).
struct RUBBLE_API AdoptionPolicy {
    double debrisKick = 0.5; ///< share of a hit's impulse that throws the debris of a *static* object outward
                             ///< (along the surface normal, spread away from the impact); dynamic objects
                             ///< already took the impulse from the physics engine
    double maxDebrisKickSpeed = 12;  ///< upper bound of that outward speed (m/s)
    double singleHullVolume = 0.25;  ///< pieces below this volume (m³) collide as one hull of their parts
    bool keepStaticRemainder = true; ///< false: every piece of a static object becomes dynamic
    double friction = 0.7;           ///< friction of piece bodies
    double restitution = 0.1;        ///< restitution of piece bodies
};

/// Structural support (SupportGraph): static parts stay up only while a chain of touching static bodies links
/// them to the ground, static scenery or an anchor.
struct RUBBLE_API SupportPolicy {
    bool collapseUnsupported =
        true;                     ///< off: the largest piece of a static object stays static, the rest falls
    double tolerance = 0.02;      ///< gap (m) between static bodies that still counts as touching
    int maxVisits = 4096;         ///< bodies one support search visits; a larger structure is supported
    int maxSearchesPerFrame = 64; ///< support searches per frame; the rest wait for the next frame
};

/// Structural stress (StructureMonitor, docs/structure.md): bonds between touching static bodies carry their
/// weight and the contact forces of moving bodies on them; a bond over its material's limit breaks and what
/// no chain of bonds holds up falls. Set at construction.
struct RUBBLE_API StructurePolicy {
    bool enabled = false;                      ///< off: support is connectivity only (SupportPolicy)
    BondSettings bonds{0.02, 1, 1e-4};         ///< what counts as a bond (gap as SupportPolicy::tolerance)
    StressSettings stress{StressMethod::Auto}; ///< the solver: converged to a relative residual of 1e-3
                                               ///< every frame; gravity is the binding's. With SweepBudget:
                                               ///< at most `iterations` sweeps a frame (ten times that in
                                               ///< the first solve after objects are placed)
    int breakRounds = 8; ///< solves after bonds break in a frame, for the new load path (converged methods)
    double damageRadius = 1.0;      ///< impacts weaken bonds within this distance (m) of the hit
    double damagePerImpulse = 1e-4; ///< health a bond at the hit loses per N·s of impulse
    bool bondDebris = false; ///< a static object's debris stays in the structure, bonded across its cut faces
                             ///< until the solver breaks it (a partial crack); false: thrown, no bonds
    double bearingFriction = 0.6; ///< > 0: objects (and what is cut from them) rest on each other as
                                  ///< bearings with this friction coefficient (compression and friction
                                  ///< only; 0.6: concrete on hardened concrete, ACI 318); 0: welded. Cut
                                  ///< faces within one object stay welded
};

/// A bond of the structure, for debug drawing.
struct RUBBLE_API StructureBond {
    BodyId a = 0, b = 0;    ///< the bodies it joins
    Vec3 centroid;          ///< interface centroid (world)
    Vec3 normal;            ///< interface normal, from a to b
    double area = 0;        ///< interface area (m²)
    double utilisation = 0; ///< largest stress / limit ratio (1 = breaking)
    double health = 1;      ///< remaining fraction of the section
};

/// A structure bond that broke, for effects (dust, decals, sound): a self-contained record.
struct RUBBLE_API StructureBreak {
    std::uint64_t frame = 0; ///< the frame it broke in (RuntimeCounters::frames)
    BodyId a = 0, b = 0;     ///< the bodies it joined, a < b
    Vec3 position;           ///< the interface centroid (world)
    Vec3 normal;             ///< the interface normal, from a to b
    double area = 0;         ///< interface area (m²)
    Vec3 force;              ///< the force it carried the moment it broke, b on a (N)
    double utilisation = 0;  ///< its largest stress over its limit (> 1 when its load broke it)
    bool damaged = false;    ///< broken by impact damage (health 0), not by its load
    std::string materialA;   ///< a's material (preset name)
    std::string materialB;   ///< b's material
};
/// A static body that lost its support and began to fall (a collapse), for effects: a self-contained record.
struct RUBBLE_API StructureCollapse {
    std::uint64_t frame = 0;     ///< the frame it began to fall in (RuntimeCounters::frames)
    BodyId body = 0;             ///< the body (dynamic from then on)
    Vec3 position;               ///< its body origin (world) when it let go
    double volume = 0, mass = 0; ///< m³, kg
    bool byStress = false;       ///< the stress solver let it go (else the support graph)
    std::string material;        ///< its object's material (preset name; empty without an object)
};

/// Budgets of the debris governor (DebrisGovernor): what keeps thousands of pieces affordable. Every resting
/// moving body that carries an object may be frozen, but only pieces are ever retired (the game's own objects
/// leave only by falling out of the world).
struct RUBBLE_API DebrisBudget {
    int maxAwakeBodies = 400;   ///< dynamic debris bodies; beyond it the slowest settling pieces
                                ///< (below settlingSpeed) freeze, then the smallest become particles
    double settlingSpeed = 1.0; ///< m/s (and rad/s): a piece this slow for 10 frames in a row may be frozen
                                ///< to hold the awake budget
    int awakeOvershoot = 16;    ///< pieces beyond maxAwakeBodies that may stay awake while they settle (new
                                ///< pieces get 10 frames, slow ones until they freeze); beyond it, hard
    double lightPerAwake = 4;   ///< moving pieces over the awake budget stop colliding with moving bodies
                                ///< (they still land on static and frozen ones) instead of retiring, up to
                                ///< this many per budgeted awake body (0, or an engine that cannot filter
                                ///< pairs: they retire)
    double physicsBudgetMs = 8; ///< physics step time no frame should exceed: the awake budget shrinks on a
                                ///< frame over it and holds the average at 55-75 % of it (ignored in
                                ///< deterministic mode, where time must not matter)
    std::size_t maxTriangles = 4000000; ///< triangles of all debris bodies (dynamic and frozen); beyond it
                                        ///< the smallest frozen pieces become particles
    bool freezeSleeping = true;         ///< a debris body the engine put to sleep is frozen (made static)
    int freezeAfterFrames = 6;          ///< ... or one that rested this many frames in a row
    double freezeSpeed = 1.0;           ///< m/s (and rad/s) below which a body not gaining speed rests
                                        ///< (velocity change under g·dt / 2 a frame; docs/architecture.md)
    double wakeImpulse = 100;           ///< impulse (N·s) that wakes a frozen piece, closing at freezeSpeed
    double fadeVolume = 0.02;           ///< debris below this volume (m³) ...
    double fadeDistance = 150;          ///< ... farther than this from the focus point fades into particles
    double killBelowY = -500;           ///< debris falling below this height retires
    double particleLifetime = 3.0;      ///< seconds a particle is drawn
};

/// A particle: a piece too small (or one too many) to simulate, drawn for a while. Its volume stays counted.
struct RUBBLE_API DebrisParticle {
    Vec3 position;       ///< world position (m)
    Vec3 velocity;       ///< world velocity (m/s)
    double size = 0;     ///< edge length of a cube of the same volume (m)
    double volume = 0;   ///< volume (m³)
    double lifetime = 0; ///< seconds left to draw it
};

/// A recent impact, for debug drawing.
struct RUBBLE_API ImpactMark {
    Vec3 point;         ///< world position
    Vec3 normal;        ///< world normal (out of the object hit)
    double impulse = 0; ///< impulse submitted
};

/// What one frame did.
struct RUBBLE_API FrameStats {
    int substeps = 0;             ///< internal physics steps
    int impactsSubmitted = 0;     ///< impacts accepted by the DestructionWorld
    int projectileHits = 0;       ///< projectiles that hit something this frame
    int fractures = 0;            ///< outcomes adopted
    int piecesCreated = 0;        ///< piece bodies created
    int piecesRetired = 0;        ///< bodies and dust turned into particles
    int piecesCollapsed = 0;      ///< static objects or pieces that lost their support and became dynamic
    int piecesFrozen = 0;         ///< debris bodies frozen
    int piecesWoken = 0;          ///< frozen bodies woken by a hit
    int supportSearches = 0;      ///< support searches run
    double supportMs = 0;         ///< of adoptMs: support (neighbour tests, searches, collapses)
    int bondsBroken = 0;          ///< structure bonds broken by stress or damage
    double structureMs = 0;       ///< of adoptMs: bond graph and stress solve
    double structureCpuMs = 0;    ///< the same stage's thread CPU time (what other processes took excluded)
    double structureResidual = 0; ///< relative residual of the stress solve the frame acted on (0: none)
    double physicsMs = 0;         ///< physics step incl. contact gathering
    double adoptMs = 0;           ///< submit + collect + adoption + governor
};

/// Pieces turned into particles, by reason.
struct RUBBLE_API RetiredPieces {
    long long dust = 0;      ///< below DestructionWorld::Config::minPieceVolume when adopted
    long long awake = 0;     ///< over the awake-body budget (or the physics time budget)
    long long triangles = 0; ///< over the triangle budget
    long long faded = 0;     ///< tiny and far from the focus
    long long fellOut = 0;   ///< below DebrisBudget::killBelowY
    /// The sum.
    long long total() const { return dust + awake + triangles + faded + fellOut; }
};

/// Totals since construction.
struct RUBBLE_API RuntimeCounters {
    std::uint64_t frames = 0;           ///< frames stepped
    long long impacts = 0;              ///< impacts accepted by the DestructionWorld
    long long projectileHits = 0;       ///< projectile hits on anything
    long long fractures = 0;            ///< outcomes adopted
    long long piecesCreated = 0;        ///< piece bodies created
    long long piecesRetired = 0;        ///< bodies and dust turned into particles (retired.total())
    RetiredPieces retired;              ///< the same, by reason
    long long piecesCollapsed = 0;      ///< static bodies that lost their support
    long long bondsBroken = 0;          ///< structure bonds broken
    long long piecesFrozen = 0;         ///< debris bodies frozen
    long long piecesWoken = 0;          ///< frozen bodies woken
    long long piecesLight = 0;          ///< moving pieces over the awake budget made light (DebrisBudget)
    long long staleOutcomes = 0;        ///< outcomes whose parent had no body
    long long collisionsOverBudget = 0; ///< collision impacts over collisionFracturesPerSecond, dropped
};

/// Where the volume of the world went (m³); live + retired + dust + dropped stays constant.
struct RUBBLE_API VolumeLedger {
    double live = 0;    ///< bodies that carry an object (static, dynamic and frozen)
    double retired = 0; ///< bodies turned into particles (budget, fading, falling out of the world)
    double dust = 0;    ///< pieces below DestructionWorld::Config::minPieceVolume
    double dropped = 0; ///< slivers the fracture kernel dropped
    /// The sum.
    double total() const { return live + retired + dust + dropped; }
};

/// Where an object's body is and how it moves (what a snapshot or a network host sends).
struct RUBBLE_API ObjectPlacement {
    ObjectId object = 0;                              ///< the object
    BodyRole role = BodyRole::Object;                 ///< an object of the scene or a piece of a fracture
    BodyMotionState motion = BodyMotionState::Static; ///< static, dynamic or frozen
    Frame objectToWorld;                              ///< world ← object coordinates
    Vec3 linearVelocity;                              ///< m/s (world)
    Vec3 angularVelocity;                             ///< rad/s (world)
};

/// Structure keys of bodies without objects (ground, scenery) in StructureBondState: this bit | the body id.
constexpr std::uint64_t kSceneryNodeKey = 1ull << 63;

/// A piece body a fracture made, for effects (dust, debris sound): a self-contained record.
struct RUBBLE_API PieceCreated {
    std::uint64_t frame = 0;     ///< the frame it was adopted in (RuntimeCounters::frames)
    BodyId body = 0;             ///< its body
    ObjectId object = 0;         ///< its object
    ObjectId parent = 0;         ///< the object it was cut from (gone once the split is committed)
    Vec3 position;               ///< its centre of mass (world)
    Vec3 velocity;               ///< its linear velocity when made (m/s, world)
    double volume = 0, mass = 0; ///< m³, kg (mass also for a piece that stays static)
    double size = 0;             ///< edge length of a cube of the same volume (m)
    double impulse = 0;          ///< Σ impulse of the impacts that broke the parent (N·s)
    bool isStatic = false;       ///< stays static (the kept part of a static object)
    std::string material;        ///< its object's material (preset name)
};

/// The runtime. Call everything from one (main) thread; fracture jobs run on the DestructionWorld's workers.
class RUBBLE_API DestructionRuntime {
public:
    /// Configuration: each component's own settings.
    struct Config {
        DestructionWorld::Config world; ///< fracture jobs (its minPieceVolume: smaller pieces become dust)
        ImpactPolicy impacts;           ///< contacts → impacts
        AdoptionPolicy adoption;        ///< outcomes → piece bodies
        SupportPolicy support;          ///< structural support and collapse
        StructurePolicy structure;      ///< structural stress
        DebrisBudget debris;            ///< the debris governor
        double projectileLifetime = 6;  ///< seconds before a projectile is removed
        double spentProjectileLifetime = 0.5; ///< seconds a projectile lives after its hit
        Config() { world.minPieceVolume = 1e-3; }
    };

    /// A runtime over the given engine.
    DestructionRuntime(PhysicsBinding& binding, Config config);
    /// Removes every body it created from the engine.
    ~DestructionRuntime();
    DestructionRuntime(const DestructionRuntime&) = delete;
    DestructionRuntime& operator=(const DestructionRuntime&) = delete;

    /// The fracture jobs and object states (read-only: the runtime alone changes them).
    const DestructionWorld& world() const;
    /// The engine.
    PhysicsBinding& binding();
    /// The settings: Config::world, Config::structure and the projectile lifetimes as constructed, the rest
    /// as last set.
    const Config& config() const;
    /// Contacts → impacts from the next frame on.
    void setImpactPolicy(const ImpactPolicy& policy);
    /// Outcomes → piece bodies from the next adoption on.
    void setAdoptionPolicy(const AdoptionPolicy& policy);
    /// Support and collapse from the next frame on.
    void setSupportPolicy(const SupportPolicy& policy);
    /// The debris governor's budgets from the next frame on.
    void setDebrisBudget(const DebrisBudget& budget);

    /// A static ground box centred at center (a root of support).
    BodyId addGround(const Vec3& center, const Vec3& halfExtents);
    /// A destructible (or indestructible) object placed at `placement` (world ← object coordinates). Static
    /// objects do not move but still break. Fails when the DestructionWorld refuses the mesh.
    Result<ObjectId> addObject(ObjectDesc desc, const Frame& placement, bool isStatic);
    /// An indestructible convex body (the hull of points in object coordinates placed at placement), mass 0 =
    /// static. Fails for fewer than 4 points or points that span no volume.
    Result<BodyId> addConvexBody(const std::vector<Vec3>& points, const Frame& placement, double mass,
                                 bool neverSleeps = false);
    /// A projectile: a sphere from `from` with `velocity`, with continuous collision detection.
    BodyId fireProjectile(const Vec3& from, const Vec3& velocity, double mass, double radius);
    /// Removes a body (a destructible object's DestructionWorld object too); what it held up is re-checked.
    void removeBody(BodyId id);
    /// Submits an impact on a body's object at a world point with a world normal (out of the object) and an
    /// impulse, e.g. for a blast. False when ignored (no destructible object, below its threshold).
    bool submitImpact(BodyId id, const Vec3& worldPoint, const Vec3& worldNormal, double impulse);
    /// Submits an impact in an object's local coordinates (as DestructionWorld::submitImpact takes it) on the
    /// object a body carries, as a contact's impact is submitted. False when ignored (no body carries the
    /// object, or the world's filter refuses it).
    bool submitLocalImpact(ObjectId object, const Impact& impact);
    /// Called with every journal event of the world (DestructionWorld::setJournalSink).
    void setJournalSink(std::function<void(const JournalEvent&)> sink);
    /// A blast on the destructible objects whose bounding spheres meet `radius` around `center`, nearest
    /// first, impulse falling to `edgeShare` at the edge: moving bodies below blastCutVolume or past
    /// blastMaxCuts are thrown (≤ blastThrowSpeed); others are hit at that sphere's point nearest the centre.
    BlastOutcome blast(const Vec3& center, double radius, double impulse, double edgeShare = 0.4);

    /// One frame, a list of stages: physics step, contacts → impacts, anchors classified, splits adopted
    /// (bodies made, then each split committed), support settled (once a frame), the onAdopted callbacks,
    /// debris governed, structure solved, particles and projectiles advanced.
    FrameStats stepFrame(double dt = 1.0 / 60);
    /// Adopts the results ready now, between frames (nothing in deterministic mode): the adoption, support
    /// and callback stages of stepFrame.
    FrameStats adoptReady();

    /// The record of a body, or null.
    const BodyRecord* body(BodyId id) const;
    /// The body carrying an object, or null.
    const BodyRecord* bodyOf(ObjectId id) const;
    /// Ids of every body, ascending (creation order).
    std::vector<BodyId> bodies() const;
    /// Where a body is (through the binding).
    BodyMotion motion(BodyId id) const;
    /// Number of bodies.
    std::size_t bodyCount() const;
    /// Piece bodies (static, dynamic and frozen).
    int livePieces() const;
    /// Dynamic debris bodies (pieces and objects).
    int awakeDebris() const;
    /// Of those, the light ones: over the awake budget, colliding with static bodies only.
    int lightDebris() const;
    /// Frozen debris bodies.
    int frozenDebris() const;
    /// Triangles of all debris bodies (what DebrisBudget::maxTriangles bounds).
    std::size_t debrisTriangles() const;
    /// The awake budget in force (DebrisBudget::maxAwakeBodies, shrunk while physics is over its budget).
    int awakeBudget() const;
    /// Particles still drawn.
    const std::vector<DebrisParticle>& particles() const;
    /// Recent impacts (oldest first).
    const std::deque<ImpactMark>& recentImpacts() const;
    /// Totals.
    const RuntimeCounters& counters() const;
    /// Where the volume went.
    VolumeLedger volumes() const;
    /// Static bodies that touch this one in the support graph (ascending), for debug drawing and tests.
    std::vector<BodyId> supportNeighbours(BodyId id) const;
    /// The structure's bonds with their stress (empty unless StructurePolicy::enabled), ordered by (a, b).
    std::vector<StructureBond> structureBonds() const;
    /// The structure bonds the last stepFrame() broke, in the order they broke (empty unless
    /// StructurePolicy::enabled).
    const std::vector<StructureBreak>& structureBreaks() const;
    /// Static bodies that fell for want of support since the last stepFrame() began (adoptReady() too).
    const std::vector<StructureCollapse>& structureCollapses() const;
    /// Piece bodies made since the last stepFrame() began (adoptReady() too), in the order they were made.
    const std::vector<PieceCreated>& createdPieces() const;
    /// The point distant debris fades from (e.g. the camera).
    void setFocus(const Vec3& point);

    /// The placement of every body that carries an object, ascending body id.
    std::vector<ObjectPlacement> placements() const;
    /// Hash of the live body set (id, role, motion, object version and mesh hash, transform bits) and of the
    /// volume ledger: equal runs give equal hashes.
    std::uint64_t stateHash() const;

    /// Called for every adopted split once the frame's support has settled: its piece bodies exist and move
    /// as they will (e.g. for the renderer).
    void setOnAdopted(std::function<void(const FractureOutcome&)> callback);
    /// Called before a body is removed (e.g. for the renderer).
    void setOnRemoved(std::function<void(const BodyRecord&)> callback);

private:
    friend class detail::StateAccess; // saving and loading (rubble/persist/WorldState.hpp)
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace rubble
