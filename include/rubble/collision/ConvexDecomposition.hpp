#pragma once
/// \file ConvexDecomposition.hpp
/// Approximate convex decomposition for collision shapes, and its incremental update at fracture time.

#include <cstdint>
#include <filesystem>
#include <list>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

struct FractureResult;
struct DecomposeControl;

/// Parameters of a decomposition.
struct RUBBLE_API DecompositionParams {
    int maxParts = 24;       ///< at most this many convex parts, in [1, kMaxConvexParts]
    double concavity = 0.02; ///< stop splitting a part whose concavity is below this fraction of the
                             ///< mesh's bounding-box diagonal
    double minPartVolumeFraction = 1e-6; ///< parts below this fraction of the mesh volume are dropped
    /// Meshes with more triangles are decomposed through a bounded proxy (vertices clustered on a grid);
    /// the parts are then the hulls of the exact mesh inside the proxy's regions (docs/megamesh.md).
    std::size_t proxyAboveTriangles = 20000;
    /// A part with more faces is replaced by a bounded polytope around it (about half as many faces, never
    /// smaller than the part), so that clipping a part costs the same whatever the mesh's triangle count.
    std::size_t maxPartFaces = 512;
};

/// InvalidInput naming the first setting out of range: maxParts in [1, kMaxConvexParts], concavity finite and
/// ≥ 0, minPartVolumeFraction in [0, 1], maxPartFaces ≥ 4. The check decompose() and DestructionWorld apply.
RUBBLE_API Status checkDecompositionParams(const DecompositionParams& params);

/// A set of convex parts approximating a closed mesh.
struct RUBBLE_API Decomposition {
    std::vector<ConvexPolytope> parts; ///< convex parts, in the mesh's coordinates
    double meshVolume = 0;             ///< volume of the mesh
    double hullVolume = 0;             ///< Σ part volumes
    /// (Σ hull volume − mesh volume) / mesh volume.
    double excess() const { return meshVolume > 0 ? (hullVolume - meshVolume) / meshVolume : 0.0; }
};

/// The convex hull of a point set (Qhull). Fails for fewer than 4 non-coplanar points.
RUBBLE_API Result<ConvexPolytope> convexHull(const std::vector<Vec3>& points);

/// A convex polytope containing every point with at most maxFaces faces: facet planes of the exact hull,
/// added where it reaches farthest out, until it reaches at most half of kPartHullTolerance out of the hull
/// (rubble/collision/CollisionTolerance.hpp); above 16 points per face, the planes of the hull of the points'
/// extremes in maxFaces / 4 directions pushed out to the farthest point. When the exact hull has at most
/// maxFaces faces it is returned instead. Fails for flat or too few points.
RUBBLE_API Result<ConvexPolytope> boundedHull(const std::vector<Vec3>& points, std::size_t maxFaces);

/// Decomposes a closed mesh into at most params.maxParts convex parts; a convex mesh gives exactly one part
/// (whatever params.concavity: a part convex to within 1e-9 of the diagonal is not split). InvalidInput for a
/// mesh that is not closed and consistently oriented, has coordinates beyond ±kMaxCoordinate or no positive
/// volume, and for maxParts outside [1, kMaxConvexParts].
RUBBLE_API Result<Decomposition> decompose(const Mesh& mesh, const DecompositionParams& params = {});

/// Incremental update at fracture time: clips the parent's parts by the cells and assigns every fragment to
/// the piece containing it. parentParts are in the same coordinates as cells and pieces. pieceCells[i] is
/// Piece::cell of piece i (-1 for remainder islands). Returns one part list per piece; a piece that received
/// no fragment gets a fresh decomposition. Slivers are dropped and parts merged to respect params.maxParts (a
/// high-poly remainder first makes its least dented parent parts whole again; docs/megamesh.md). A
/// remainder's parts stay out of the cells' debris and may number up to kCraterBudgetFactor × maxParts to do
/// so; every piece's parts stay within kPartHullTolerance of its convex hull (docs/collision.md).
RUBBLE_API std::vector<std::vector<ConvexPolytope>>
updateDecomposition(const std::vector<ConvexPolytope>& parentParts, const std::vector<ConvexPolytope>& cells,
                    const std::vector<Mesh>& pieces, const std::vector<std::int32_t>& pieceCells,
                    const DecompositionParams& params = {});
/// updateDecomposition for the pieces of a fracture (rubble/fracture/Fracture.hpp): one part list per piece
/// of result.
RUBBLE_API std::vector<std::vector<ConvexPolytope>>
updateDecomposition(const std::vector<ConvexPolytope>& parentParts, const FractureResult& result,
                    const DecompositionParams& params = {});

/// Thread-safe cache of decompositions keyed by Mesh::hash(), optionally persisted in a directory. The memory
/// holds at most capacity() entries: on a miss beyond that, the least recently used entry is evicted (its
/// file, if any, stays on disk), so a long run that adds many distinct meshes uses bounded memory.
class RUBBLE_API DecompositionCache {
public:
    /// Default in-memory capacity (entries).
    static constexpr std::size_t kDefaultCapacity = 256;
    /// An in-memory cache of at most capacity entries (0 is taken as 1); with a directory, entries are also
    /// read from and written to files there.
    explicit DecompositionCache(std::filesystem::path directory = {},
                                std::size_t capacity = kDefaultCapacity);
    /// The cached decomposition of mesh, computing and storing it on a miss.
    Result<Decomposition> get(const Mesh& mesh, const DecompositionParams& params = {});
    /// get, decomposing a miss under control (rubble/collision/DecomposeControl.hpp): its threads, progress
    /// and cancel. A hit reports progress 1 at once; a cancelled decomposition is neither kept nor written.
    Result<Decomposition> get(const Mesh& mesh, const DecompositionParams& params,
                              const DecomposeControl& control);
    /// Number of lookups answered from the cache (memory or disk).
    std::size_t hits() const;
    /// Number of entries held in memory (never more than capacity()).
    std::size_t size() const;
    /// The most entries held in memory.
    std::size_t capacity() const { return capacity_; }

private:
    struct Entry {
        Decomposition decomposition;
        std::list<std::uint64_t>::iterator recency; // position in recency_
    };
    // Stores (or refreshes) key under the lock, evicting the least recently used entries beyond capacity_.
    void store(std::uint64_t key, const Decomposition& d);

    std::filesystem::path directory_;
    std::size_t capacity_;
    mutable std::mutex mutex_;
    std::unordered_map<std::uint64_t, Entry> memory_;
    std::list<std::uint64_t> recency_; // most recently used first
    std::size_t hits_ = 0;
};

} // namespace rubble
