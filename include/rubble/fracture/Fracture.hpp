#pragma once
/// \file Fracture.hpp
/// The fracture kernel: cells around an impact, booleans against them, pieces with mass properties.
/// Pure functions of their inputs and a seed; no physics engine involved.

#include <cstdint>
#include <memory>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/fracture/Roughness.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

struct MeshTopology; // a large mesh's half-edge twins (internal: src/geometry/MeshTopology.hpp)

/// An impact on an object, in the object's mesh coordinates.
struct RUBBLE_API Impact {
    Vec3 point; ///< where the object was hit
    Vec3 normal{0, 1,
                0}; ///< surface normal at the hit (pointing out of the object), or the hit direction reversed
    double impulse = 1; ///< magnitude of the applied impulse (N·s)
};

/// How the size of the cut region follows the impulse: size = clamp(base + scale · impulse^exponent, min,
/// max), where size is the edge length of the cubic domain the cell is built in.
struct RUBBLE_API CellSizeLaw {
    double base = 0.5;     ///< size at zero impulse
    double scale = 0.05;   ///< growth factor
    double exponent = 0.5; ///< growth exponent
    double minSize = 0.05; ///< lower clamp
    double maxSize = 20;   ///< upper clamp
    /// The domain size for an impulse.
    double sizeFor(double impulse) const;
};

/// Which cells an impact cuts.
enum class CellPattern {
    SingleCell, ///< the thesis: the Voronoi cell of the impact point among random seeds in a box domain
    Shatter,    ///< K Voronoi cells around the impact, denser near it, randomly rotated and scaled
    Adaptive,   ///< per impact (impactCut): a weak hit chips one cell, a strong hit shatters; the cut grows
                ///< with the object's size
};

/// Which boolean implementation runs.
enum class BooleanKind {
    Corefine, ///< CGAL Polygon_mesh_processing corefinement (exact; the fallback of Fast)
    Nef,      ///< CGAL Nef_polyhedron_3 (the thesis's method; reference and cross-check)
    Fast, ///< default: Rubble's convex-cell clipper, touching only triangles near the cells; implemented by
          ///< detail::clipByConvexCells (src/fracture/ConvexCellClipper.hpp), all cells in one pass as a
          ///< complex (adjacent shatter cells share their faces exactly); when it
          ///< declines a near-degenerate configuration, or its split fails verification, the whole split is
          ///< redone by Corefine (FractureStats::exactFallback). fracture() first redraws a declined
          ///< pattern up to twice (FractureStats::redraws). Same seed, same bytes, like the others.
};

/// Where a Shatter pattern's cells lie around the impact (a material's fracture pattern, Material.hpp).
enum class ShatterLayout : std::uint8_t {
    Clustered, ///< fine cells near the impact, coarse further away (concrete, stone, brick)
    Radial,    ///< wedges between radial cracks, in rings, in the plane across the impact normal (glass)
    Splinter,  ///< cells long along the grain, the longest axis of the mesh's bounds (wood)
    Uniform,   ///< evenly sized cells (steel)
};

/// What one impact cuts: the pattern and the edge of its cubic domain (impactCut).
struct RUBBLE_API ImpactCut {
    CellPattern pattern = CellPattern::SingleCell; ///< SingleCell or Shatter
    double size = 0;                               ///< domain edge length
};

/// CellPattern::Adaptive: a hit shatters when its law size is at least this many times a touch's
/// (sizeFor(0)).
inline constexpr double kShatterGrowth = 3.0;
/// CellPattern::Adaptive: objects with a bounds diagonal above this lose cuts larger by sqrt(diagonal / it).
inline constexpr double kAdaptiveReferenceSize = 10.0;

/// Parameters of one fracture.
struct RUBBLE_API FractureParams {
    CellPattern pattern = CellPattern::SingleCell; ///< single cell (thesis) or shatter pattern
    int seedPoints = 15; ///< random Voronoi sites in the domain besides the impact point
    int cells = 16;      ///< K, the cells of a Shatter pattern: 1..kMaxShatterCells (fracture refuses others)
    ShatterLayout layout = ShatterLayout::Clustered; ///< where a Shatter pattern's cells lie
    CellSizeLaw sizeLaw;                             ///< domain size from impulse
    BooleanKind backend = BooleanKind::Fast;         ///< boolean implementation
    double minPieceVolumeFraction = 1e-9; ///< pieces below this fraction of the input volume are dropped
                                          ///< (their volume is reported in FractureResult::droppedVolume)
    double uvScale = 1.0;                 ///< texture repeats per unit length on cut faces
    bool simplifyPieces = true;           ///< remove the vertices that carry no shape from every piece
                                          ///< (simplifyPlanarRegions, lossless): bounds the triangle count of
                                          ///< pieces that are hit again and again
    /// The cut-surface model: flat (the thesis's cut) by default; rough with the Fast backend, which then
    /// cuts by copy, not in place (docs/roughness.md). fracture() mixes its seed into roughness.seed.
    Roughness roughness;
};

/// A MeshTopology held by value: copied and compared with the facts that hold it; empty when unknown.
class RUBBLE_API HeldTopology {
public:
    HeldTopology() noexcept;
    HeldTopology(MeshTopology&& topology); ///< holds topology (nothing when it is empty)
    HeldTopology(const HeldTopology& other);
    HeldTopology(HeldTopology&& other) noexcept;
    HeldTopology& operator=(const HeldTopology& other);
    HeldTopology& operator=(HeldTopology&& other) noexcept;
    ~HeldTopology();
    /// True when no topology, or an empty one, is held.
    bool empty() const;
    /// The topology, or null.
    const MeshTopology* get() const { return held_.get(); }
    /// The topology, or null.
    MeshTopology* get() { return held_.get(); }
    /// True when a topology is held and sized for mesh (it must also belong to mesh, as MeshFacts do).
    bool fits(const Mesh& mesh) const;
    /// Both empty, or the same twins.
    bool operator==(const HeldTopology& other) const;

private:
    std::unique_ptr<MeshTopology> held_;
};

/// What is known of a mesh, so that fracturing it skips the passes over the whole mesh that would find it
/// again: that it is a valid closed, consistently oriented solid, and its volume integrals. analyzeMesh finds
/// them once (e.g. when an object is added); every Piece carries them for its own mesh, so a piece that is
/// hit again is not scanned again. They belong to one mesh, unchanged: facts whose counts do not match the
/// mesh are ignored, and facts of another mesh with the same counts give wrong results.
struct RUBBLE_API MeshFacts {
    bool known = false;        ///< false: nothing is known (fracture checks and measures everything)
    std::size_t triangles = 0; ///< the mesh's triangle count
    std::size_t vertices = 0;  ///< the mesh's vertex count
    VolumeIntegrals integrals; ///< of the mesh (its mass properties are massProperties(integrals))
    /// Of a mesh above 20k triangles that is one shell (analyzeMesh; pieces of a fracture given it), else
    /// empty: with it, the consuming fracture edits the mesh in place and checks only around the cut.
    HeldTopology topology{};
    /// True when these are facts of a mesh with mesh's counts.
    bool fit(const Mesh& mesh) const {
        return known && triangles == mesh.triangles.size() && vertices == mesh.positions.size();
    }
};

/// Checks that mesh is a valid closed, consistently oriented solid of positive volume (as fracture does) and
/// returns its facts; InvalidInput otherwise.
RUBBLE_API Result<MeshFacts> analyzeMesh(const Mesh& mesh);

/// One output piece: a closed, outward-oriented mesh in the input's coordinates.
struct RUBBLE_API Piece {
    Mesh mesh;              ///< closed mesh; cut faces have material kInteriorMaterial and planar UVs
    MassProperties mass;    ///< exact mass properties of mesh (density 1)
    std::int32_t cell = -1; ///< -1: part of the damaged remainder (input − cells); i ≥ 0: debris of cell i
    MeshFacts facts;        ///< what is known of mesh: pass it to the next fracture of this piece
};

/// Durations of the stages of one fracture, in milliseconds.
struct RUBBLE_API FractureTimings {
    double validateMs = 0; ///< checking that the input mesh is a valid closed, oriented solid
    double cellMs = 0;     ///< building the cells
    double booleanMs = 0;  ///< difference and intersections
    double verifyMs = 0;   ///< of booleanMs: checking that the split's outputs are closed and keep the volume
    double islandsMs = 0;  ///< splitting into islands and mass properties (includes massMs)
    double massMs = 0;     ///< of islandsMs: mass properties of the pieces and interior UVs
    double simplifyMs = 0; ///< of islandsMs: simplifying the pieces' flat regions
    double totalMs = 0;    ///< everything
};

/// How one fracture went: the path it took and its stage durations (diagnostics; not part of the pieces).
struct RUBBLE_API FractureStats {
    bool exactFallback = false; ///< Fast declined or failed verification; Corefine made the split
    int redraws = 0; ///< fracture() with Fast: cell patterns redrawn (from derived seeds) because the clipper
                     ///< declined a near-degenerate one; 0 = the seed's own pattern
    bool editedInPlace = false; ///< the remainder is the input edited in place (MeshFacts::topology)
    bool rough = false;         ///< the cut faces were roughened (roughness active, the clipper's split kept)
    bool islandsLabelledFully = false; ///< edited in place, but the walk around the cut did not prove the
                                       ///< remainder one shell: it was labelled in full (a cavity)
    bool islandsByRace = false; ///< edited in place, and the remainder's islands were found by walks racing
                                ///< from the cut (docs/megamesh.md), not by labelling it in full
    FractureTimings timings;    ///< stage durations, wall clock
    FractureTimings cpuTimings; ///< the same stages in the calling thread's CPU time (on a shared machine)
};

/// Everything one fracture produced.
struct RUBBLE_API FractureResult {
    std::vector<Piece> pieces;         ///< remainder islands first, then debris islands by cell
    std::vector<ConvexPolytope> cells; ///< the cells that were cut (faces tagged with their plane index)
    double inputVolume = 0;            ///< volume of the input mesh
    double droppedVolume = 0;          ///< volume of pieces dropped as too small
    FractureStats stats;               ///< how it went
    std::vector<double> concavity;     ///< per piece, its parts' partConcavity (-1: none); opt-in, see
                                       ///< recordConcavity (rubble/collision/PartConcavity.hpp)
};

/// The cut of one impact on a mesh with the given bounds. SingleCell and Shatter: the params' pattern and
/// sizeLaw.sizeFor(impulse). Adaptive: Shatter when sizeFor(impulse) >= kShatterGrowth * sizeFor(0), else
/// SingleCell; the size is sizeFor(impulse) * max(1, sqrt(diagonal / kAdaptiveReferenceSize)), at most
/// sizeLaw.maxSize (demo/README.md, weapons). Pure; a function of the journaled impulse and the geometry.
RUBBLE_API ImpactCut impactCut(const FractureParams& params, const Aabb& meshBounds, double impulse);

/// Builds the cutting cells of an impact on a mesh with these bounds (clamps cells); deterministic in seed.
RUBBLE_API std::vector<ConvexPolytope> generateCells(const Aabb& meshBounds, const Impact& impact,
                                                     const FractureParams& params, std::uint64_t seed);

/// The checks of the parameter table (rubble/core/ParameterCheck.hpp) on an impact's point, normal and
/// impulse and on params' cells: what fracture() refuses.
RUBBLE_API Status checkFractureParams(const Impact& impact, const FractureParams& params);

/// Fractures a closed mesh at an impact: cells, booleans, islands, mass properties, interior UVs.
/// NoIntersection when the cells miss the mesh; InvalidInput for an open mesh or checkFractureParams'
/// refusals. With known facts of mesh (analyzeMesh, Piece::facts), the mesh is not validated again and, with
/// the Fast backend, the remainder's mass properties follow from the mesh's by difference (equal to a full
/// recomputation up to rounding; docs/megamesh.md); the pieces' meshes are the same either way.
/// With known facts that carry a topology (MeshFacts::topology) and the Fast backend, a copy of the mesh and
/// its facts is cut in place. These four are shorthands for fracture(FractureRequest) (FractureRequest.hpp).
RUBBLE_API Result<FractureResult> fracture(const Mesh& mesh, const Impact& impact,
                                           const FractureParams& params, std::uint64_t seed,
                                           const MeshFacts& known = {});

/// fracture, consuming the mesh and its facts: with a topology in them and the Fast backend, the remainder
/// is the input edited in place (the triangles the cut removed replaced by those it made, checked closed
/// around the cut only; its islands found by a walk around the cut, with a full labelling as the proven
/// fallback) and keeps an updated topology, so the cost follows the cut (docs/megamesh.md). Its triangles are
/// then in a different order than the copying path gives, and it may keep unreferenced vertices (compacted
/// when they are many). Without a topology it is the const& overload.
RUBBLE_API Result<FractureResult> fracture(Mesh&& mesh, const Impact& impact, const FractureParams& params,
                                           std::uint64_t seed, MeshFacts known = {});

/// Fractures a closed mesh with explicitly given cells (for merged impacts and tests); known as for fracture.
RUBBLE_API Result<FractureResult> fractureWithCells(const Mesh& mesh, std::vector<ConvexPolytope> cells,
                                                    const FractureParams& params,
                                                    const MeshFacts& known = {});

/// fractureWithCells consuming the mesh and its facts, as the consuming fracture.
RUBBLE_API Result<FractureResult> fractureWithCells(Mesh&& mesh, std::vector<ConvexPolytope> cells,
                                                    const FractureParams& params, MeshFacts known = {});

} // namespace rubble
