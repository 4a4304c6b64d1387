#pragma once
/// \file DestructionWorld.hpp
/// The engine-agnostic runtime: impacts in, fracture jobs on a JobSystem, versioned results out.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Export.hpp"
#include "rubble/core/Frame.hpp"
#include "rubble/core/JobSystem.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/runtime/Journal.hpp"

namespace rubble {

namespace detail {
class StateAccess; // src/runtime/StateAccess.hpp
} // namespace detail

/// Identifies a destructible object in a DestructionWorld (never reused).
using ObjectId = std::uint32_t;

/// What an object is made of.
struct RUBBLE_API ObjectDesc {
    Mesh mesh;                   ///< closed mesh in the object's local coordinates
    double density = 1;          ///< mass = density · volume
    bool destructible = true;    ///< false: never fractured
    double impulseThreshold = 0; ///< impacts below this impulse are ignored
    FractureParams fracture;     ///< how it breaks
    std::vector<ConvexPolytope>
        convexParts;      ///< collision parts in local coordinates; empty = decompose on add
    std::string material; ///< structural material, a Material.hpp preset (empty: defaultMaterial())
};

/// A live object as the runtime sees it.
struct RUBBLE_API ObjectState {
    ObjectId id = 0;           ///< its id
    std::uint32_t version = 0; ///< bumped whenever its shape is replaced
    Mesh mesh; ///< local mesh: a piece's is in its principal frame (origin at the centre of mass), but for
               ///< a remainder above 20k triangles cut in place, which keeps its parent's frame
    MassProperties mass;         ///< mass properties of mesh, density 1
    double density = 1;          ///< density
    bool destructible = true;    ///< false when never fractured (also: mesh could not be made valid)
    double impulseThreshold = 0; ///< minimum impulse that fractures it
    FractureParams fracture;     ///< how it breaks
    std::vector<ConvexPolytope> convexParts; ///< collision parts in local coordinates
    std::string warning;                     ///< why it is indestructible, when it had to be made so
    std::size_t crumbleAbove = 0; ///< a hit on it crumbles it once its mesh has more triangles than this
                                  ///< (see Config::crumbleTriangles; pieces inherit their parent's)
    std::uint64_t meshHash = 0;   ///< mesh.hash(), computed once when the object is made (restoreState takes
                                  ///< a saved one as it is; 0 there: computed), or for a remainder cut in
                                  ///< place when first read (0 until geometryHash() or captureState())
};

/// Wall-clock timing of one impact from submission to adoption, in milliseconds. For an adopted job the
/// stages follow one another without gaps:
/// queue + prepare + cell + boolean + islands + decomposition + finish + handoff + adoption = total.
struct RUBBLE_API TimingRecord {
    ObjectId object = 0;        ///< the object that was hit
    std::uint64_t frame = 0;    ///< frame of submission
    int impactsMerged = 1;      ///< impacts fractured in this job
    double queueMs = 0;         ///< waiting for a worker (and for an in-flight job on the same object)
    double prepareMs = 0;       ///< moving the impacts onto the surface, checking the input mesh, and the
                                ///< job's copy of a large mesh that the fracture edits in place
    double cellMs = 0;          ///< building cells
    double booleanMs = 0;       ///< booleans (with the check that the pieces close up)
    double islandsMs = 0;       ///< islands, cut-face attributes, simplification, mass properties
    double decompositionMs = 0; ///< convex parts of the pieces
    double finishMs = 0;        ///< pieces moved into their principal frames, with their mass properties
    double handoffMs = 0;       ///< the finished job waiting for the main thread to collect it
    double adoptionMs = 0;      ///< main-thread adoption: from collect() handing the split out to commit()
                                ///< (the engine's bodies and collision shapes included)
    double totalMs = 0;         ///< submission → adopted
    int pieces = 0;             ///< pieces produced
    bool stale = false;         ///< discarded because the object changed meanwhile
    bool missed = false; ///< the impact's cells did not intersect the mesh (ErrorCode::NoIntersection, e.g.
                         ///< an impact that waited on an in-flight job and was re-targeted to a piece while
                         ///< its point lies in the removed crater): nothing to break, the object stays and
                         ///< impacts that waited on the job are retried. Not a failure.
    bool failed = false; ///< the fracture failed on the geometry (any other error): the object stays and
                         ///< impacts that waited on the job are retried
    bool crumbled =
        false; ///< the object was over its triangle limit: the hit crumbled it (Config::crumbleTriangles)
    std::uint64_t touchedTriangles = 0; ///< triangles the job's own passes after the kernel read (a piece
                                        ///< moved into its frame, measured and hashed counts 4 per triangle)
};

/// A child of a split: a new object of the world once the split is committed.
struct RUBBLE_API AdoptedPiece {
    ObjectId id = 0;        ///< the new object's id (added to the world by DestructionWorld::commit)
    Frame frame;            ///< piece local frame → parent local frame (centre of mass, principal axes;
                            ///< the identity for a remainder that keeps its parent's frame)
    std::int32_t cell = -1; ///< Piece::cell: −1 part of the remainder, i ≥ 0 debris of cell i
    std::shared_ptr<const ObjectState> state; ///< its mesh, mass properties and convex parts
};

/// A piece below the world's minimum volume (Config::minPieceVolume): never made an object, only reported,
/// so that the engine can show it as a particle and keep its volume counted.
struct RUBBLE_API DustPiece {
    Vec3 center;            ///< its centre of mass (parent local coordinates)
    double volume = 0;      ///< its volume
    std::int32_t cell = -1; ///< Piece::cell
};

/// A split event: one self-contained record of a fracture ready to adopt, the parent object and the pieces
/// that replace it (their frames, meshes, mass properties and convex parts) when it is committed.
struct RUBBLE_API FractureOutcome {
    ObjectId parent = 0;              ///< the object that broke (replaced by DestructionWorld::commit)
    std::uint32_t parentVersion = 0;  ///< its version when the job started
    std::vector<AdoptedPiece> pieces; ///< the new objects
    std::vector<DustPiece> dust;      ///< pieces too small to become objects
    std::vector<Impact> impacts;      ///< the impacts (parent local coordinates) that caused it
    double droppedVolume = 0;         ///< volume of slivers the kernel dropped (for volume bookkeeping)

    /// Σ volume of dust.
    double dustVolume() const;
    /// Σ impulse of the impacts (N·s).
    double impulse() const;
};

/// The runtime. All member functions are called from one (main) thread; work runs on the JobSystem.
class RUBBLE_API DestructionWorld {
public:
    /// Configuration.
    struct Config {
        JobSystem* jobs = nullptr;  ///< null: an owned ThreadPool with hardware threads − 1 workers (≥ 1)
        int workers = -1;           ///< worker count of the owned pool (-1 = automatic)
        bool deterministic = false; ///< adopt each result exactly delayFrames after its impact
        int delayFrames = 2;        ///< frame delay in deterministic mode
        double adoptionBudgetMs = 1.0; ///< main-thread ms a frame for adoption (at least one result adopts)
        std::uint64_t seed = 1; ///< world seed; each job's seed derives from it, the object and version
        DecompositionParams decomposition; ///< convex parts of pieces
        /// Every crater adds faces, so an object hit again and again would grow without bound. Once an
        /// object's mesh has more triangles than max(crumbleTriangles, twice the triangles it was added
        /// with), a hit crumbles it instead: crumbleCells shatter cells as large as the object break it into
        /// a few big pieces (which the engine adapter can let fall and retire). 0 = never.
        std::size_t crumbleTriangles = 16384;
        int crumbleCells = 4; ///< cells of a crumbling hit
        /// timings() keeps at least this many of the latest records and at most twice as many, so a long game
        /// does not accumulate them forever (0 = keep all).
        std::size_t keepTimings = 16384;
        /// Pieces below this volume are not made objects; a FractureOutcome reports them as dust.
        double minPieceVolume = 0;
    };

    /// InvalidInput naming the first setting out of range (the decomposition's, delayFrames, crumbleCells,
    /// minPieceVolume, adoptionBudgetMs, workers). A world built with such a config refuses every addObject.
    static Status checkConfig(const Config& config);
    /// A world with the given configuration.
    explicit DestructionWorld(Config config);
    /// Waits for in-flight jobs to finish (or discards their results); never hangs.
    ~DestructionWorld();
    DestructionWorld(const DestructionWorld&) = delete;
    DestructionWorld& operator=(const DestructionWorld&) = delete;

    /// Adds an object. An open or invalid mesh is repaired when possible, else the object becomes
    /// indestructible and ObjectState::warning says why. Fails for an empty mesh, a bad density or cells.
    Result<ObjectId> addObject(ObjectDesc desc);
    /// Removes an object (pending work for it is discarded).
    void removeObject(ObjectId id);
    /// The object, or null when it does not exist (any more).
    const ObjectState* object(ObjectId id) const;
    /// Ids of all live objects, ascending.
    std::vector<ObjectId> objects() const;

    /// The impact filter: whether submitImpact accepts this impact (object-local): a live destructible
    /// object, the impulse at single precision (journalPrecision) at least the object's threshold, and an
    /// impact checkFractureParams accepts.
    bool accepts(ObjectId id, const Impact& impact) const;
    /// Submits an impact in the object's local coordinates. Returns false when accepts() refuses it. An
    /// impact on an object with a job in flight is merged into the next job for that object. Accepted:
    /// rounded to single precision (journalPrecision) and journaled.
    bool submitImpact(ObjectId id, const Impact& impact);

    /// Called with every journal event as it happens: each accepted impact and each removal of a live object.
    void setJournalSink(std::function<void(const JournalEvent&)> sink);
    /// Journal events so far (the position a snapshot records).
    std::uint64_t journalPosition() const;
    /// Applies one journal event now (as submitImpact or removeObject would). Fails, changing nothing, when
    /// the object does not exist, refuses the impact, or its fracture pattern or next job seed differ from
    /// the event's (a journal of another scene or world seed).
    Status applyJournalEvent(const JournalEvent& event);

    /// Order-independent hash of the geometry: every live object's id, version and mesh hash. Equal worlds
    /// give equal hashes on any worker count and compiler (docs/journal.md). O(1): kept up to date.
    std::uint64_t geometryHash() const;

    /// Advances the frame counter; call once per frame before collect().
    void beginFrame();
    /// The current frame number.
    std::uint64_t frame() const;
    /// The split events ready this frame (within the adoption budget), one per broken object. The world does
    /// not change yet: the caller makes the pieces' bodies, then calls commit() once for each split.
    std::vector<FractureOutcome> collect();
    /// Commits a split of collect() once the engine's bodies exist: the pieces replace the parent object,
    /// impacts that waited for its job go to the piece nearest to them, and the split's TimingRecord ends
    /// (its adoptionMs and totalMs include the engine's part). Until then the parent stays, and impacts on
    /// it wait. No effect when called again, or when the parent was removed meanwhile (the record is stale).
    void commit(const FractureOutcome& split);
    /// Blocks until a finished job waits for collect() or until deadline passes; true when one does. For
    /// adopting results in the main thread's idle time between frames (collect() may be called again in
    /// the same frame). Returns false at once when no job is in flight, and always in deterministic mode,
    /// where adoption stays bound to frames so that replays are identical. A deadline in the past polls.
    bool waitForResult(std::chrono::steady_clock::time_point deadline) const;
    /// Blocks until no job is in flight or queued (for tools, tests and shutdown).
    void waitIdle() const;

    /// Jobs running or waiting.
    int jobsInFlight() const;
    /// Timing of the finished impacts, oldest first (the latest Config::keepTimings to twice as many).
    const std::vector<TimingRecord>& timings() const;
    /// Sequence number of timings().front(): how many older records were dropped to keep timings() bounded.
    /// Record k of the game (counting from 0) is timings()[k − firstTimingRecord()] while it is kept, so a
    /// reader that resumes where it left off across frames keeps a sequence number, not an index.
    std::uint64_t firstTimingRecord() const;
    /// Writes timings() as CSV.
    Status writeTimingsCsv(const std::filesystem::path& path) const;

private:
    friend class detail::StateAccess; // saving and loading (rubble/persist/WorldState.hpp)
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace rubble
