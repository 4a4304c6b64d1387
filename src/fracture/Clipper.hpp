#pragma once
// The fast clipper's state and stages (ConvexCellClipper.hpp is its interface): the complex
// (CellComplex.cpp), the triangle clip (ClipTriangle.cpp), the caps (ClipCaps.cpp) and the output
// (ClipOutput.cpp); ConvexCellClipper.cpp runs them.

#include "CellComplex.hpp"
#include "ConvexCellClipper.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "rubble/geometry/MassProperties.hpp"

namespace rubble::detail::clip {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

/// Key of a created point: which mesh edge / triangle and which cell planes or complex edge it lies on.
struct PointKey {
    // 1: mesh edge (a<b) ∩ face c; 2: triangle a ∩ complex edge (b<c); 3: complex vertex a;
    // 4: triangle a ∩ faces b<c that share no edge (never a corner of an output)
    std::uint32_t kind;
    std::uint32_t a, b, c;
    bool operator==(const PointKey&) const = default;
};
struct PointKeyHash {
    std::size_t operator()(const PointKey& k) const {
        std::uint64_t h = k.kind * 0x9E3779B97F4A7C15ull;
        h ^= (std::uint64_t(k.a) + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull;
        h = (h << 17) | (h >> 47);
        h ^= (std::uint64_t(k.b) << 32 | k.c) * 0x94D049BB133111EBull;
        return static_cast<std::size_t>(h ^ (h >> 29));
    }
};

/// What an edge of a clipped polygon lies on.
struct Support {
    bool onMeshEdge; // true: the mesh edge (a,b) with a<b; false: the cut line of complex face a
    std::uint32_t a, b;
};

/// A polygon corner and the support of the edge to the next corner.
struct Corner {
    std::uint32_t id;
    Support next;
};

/// Splits a mesh by a complex of convex cells in one pass: every point is computed once, from the input
/// mesh and the complex, and shared by every region that uses it.
class Clipper {
public:
    /// The cells' bounds and the clip's tolerance (relative to their size and distance from the origin).
    struct Scale {
        Aabb box;
        double eps = 0;
    };
    static Scale scaleOf(const std::vector<ConvexPolytope>& cells) {
        Scale s;
        for (const ConvexPolytope& c : cells)
            s.box.extend(c.bounds());
        double maxAbs = 0;
        for (int a = 0; a < 3; ++a)
            maxAbs = std::max({maxAbs, std::abs(s.box.lo[a]), std::abs(s.box.hi[a])});
        s.eps = std::max(1e-10 * s.box.diagonal(), 1e-14 * maxAbs);
        return s;
    }

    /// A clipper of mesh by the complex of cells built at scale (buildCellComplex(cells, scale.eps)).
    Clipper(const Mesh& mesh, const Scale& scale, CellComplex cx)
        : mesh_(mesh), cx_(std::move(cx)), box_(scale.box), eps_(scale.eps) {
        nV_ = static_cast<std::uint32_t>(mesh.positions.size());
        k_ = static_cast<std::uint32_t>(cx_.cells.size());
        nF_ = static_cast<std::uint32_t>(cx_.faces.size());
        cutEdges_.resize(nF_);
        untouched_.resize(k_ + 1);
        tris_.resize(k_ + 1);
        thread_local SlotArray threadSlots;
        slots_ = threadSlots.busy ? &ownSlots_ : &threadSlots;
        slots_->busy = true;
        if (slots_->slot.size() < nV_)
            slots_->slot.resize(nV_, -1);
        distSlot_ = slots_->slot.data();
    }
    ~Clipper() {
        for (std::uint32_t v : slots_->set)
            distSlot_[v] = -1;
        slots_->set.clear();
        slots_->busy = false;
    }
    Clipper(const Clipper&) = delete;
    Clipper& operator=(const Clipper&) = delete;

    /// Region k < K: mesh ∩ cell k; region K: the rest. With known (the mesh's integrals), outside gets the
    /// rest's integrals by difference.
    /// With edit (and known), the rest is not assembled but returned as an edit of the mesh (the last
    /// region of the result is then empty).
    /// GeometryFailure ("fast clip declined: ...") for a configuration it does not handle robustly.
    Result<std::vector<Mesh>> run(const VolumeIntegrals* known, std::optional<VolumeIntegrals>& restIntegrals,
                                  RemainderEdit* edit = nullptr);
    /// After run: the triangles region r kept whole (assemble puts them first).
    std::size_t keptWhole(std::uint32_t r) const { return untouched_[r].size(); }

private:
    const Mesh& mesh_;
    CellComplex cx_;
    // Why run declines: the first configuration a stage found it does not handle robustly.
    const char* declined_ = nullptr;

    /// Records why the clip declines (the first reason); kNone for a stage that returns a point.
    std::uint32_t decline(const char* why) {
        if (!declined_)
            declined_ = why;
        return kNone;
    }
    Aabb box_;
    double eps_ = 0;
    std::uint32_t nV_ = 0, k_ = 0, nF_ = 0;

    std::vector<Vec3> extra_;   // created points, ids nV_ + i
    std::vector<bool> offEdge_; // per created point: kind 4 (may not end up in an output)
    std::unordered_map<PointKey, std::uint32_t, PointKeyHash> keyed_;
    // Per mesh vertex: offset into dist_ or -1; a per-thread array, reset only at the vertices it set.
    struct SlotArray {
        std::vector<std::int32_t> slot;
        std::vector<std::uint32_t> set; // the vertices whose slot is not -1
        bool busy = false;
    };
    SlotArray ownSlots_; // used when the thread's array is taken (a clip inside a clip)
    SlotArray* slots_ = nullptr;
    std::int32_t* distSlot_ = nullptr;
    std::vector<double> dist_; // distances to every complex face plane

    // Per complex face: the directed cut edges of its back cell's polygons on that face.
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> cutEdges_;
    // Per complex edge (a<b): points where it pierces the mesh surface.
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> pierce_;

    // Output triangles by point id, with the source triangle (kNone for cap faces) and cap face.
    struct OutTri {
        std::uint32_t v[3];
        std::uint32_t source; // mesh triangle it lies in, or kNone for a cap
        std::uint32_t face;   // complex face of a cap
        bool flipped;         // cap seen from the face's front
    };
    std::vector<std::vector<OutTri>> tris_;             // per region
    std::vector<std::vector<std::uint32_t>> untouched_; // per region: input triangles kept whole

    const Vec3& pos(std::uint32_t id) const { return id < nV_ ? mesh_.positions[id] : extra_[id - nV_]; }

    /// Signed distance to complex face f's plane (positive in front).
    double dist(std::uint32_t id, std::uint32_t f) const {
        if (id < nV_)
            return dist_[static_cast<std::size_t>(distSlot_[id]) + f];
        return cx_.faces[f].plane.signedDistance(extra_[id - nV_]);
    }
    /// Signed distance to the l-th plane of cell c (positive outside the cell).
    double cellDist(std::uint32_t id, std::uint32_t c, std::size_t l) const {
        const double d = dist(id, cx_.cells[c].faces[l]);
        return cx_.cells[c].flipped[l] ? -d : d;
    }

    void ensureDistances(std::uint32_t v) {
        if (distSlot_[v] >= 0)
            return;
        distSlot_[v] = static_cast<std::int32_t>(dist_.size());
        slots_->set.push_back(v);
        for (const CellComplex::Face& f : cx_.faces)
            dist_.push_back(f.plane.signedDistance(mesh_.positions[v]));
    }

    std::uint32_t addPoint(const PointKey& key, const Vec3& p, bool offEdge = false) {
        auto [it, inserted] = keyed_.emplace(key, nV_ + static_cast<std::uint32_t>(extra_.size()));
        if (inserted) {
            extra_.push_back(p);
            offEdge_.push_back(offEdge);
        }
        return it->second;
    }

    std::uint32_t crossing(std::uint32_t tri, std::uint32_t cell, const Support& s, std::uint32_t face,
                           std::uint32_t from, std::uint32_t to, double dFrom, double dTo);
    std::vector<Corner> clipTriangle(std::uint32_t t, std::uint32_t cell);
    void cutTriangle(std::uint32_t t, const std::vector<std::uint32_t>& cells);
    void emitConvex(const std::vector<std::uint32_t>& poly, const Vec3& normal, std::uint32_t source,
                    std::vector<OutTri>& out);
    void triangulateRegion(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                           std::size_t boundaryEdges, const Vec3& normal, std::uint32_t source,
                           std::uint32_t face, std::vector<OutTri>& out);
    void buildCaps();
    bool pointInsideMesh(const Vec3& p) const;
    void emitAttributes(const OutTri& o, std::vector<Vec3f>* normals, std::vector<Vec2f>& uvs,
                        std::vector<std::uint32_t>& materials) const;
    Mesh assemble(std::uint32_t region) const;
    RemainderEdit assembleEdit(std::vector<std::uint32_t> removed) const;
};

/// Null when every directed edge of the new triangles that touches a created point has its twin among them,
/// else why not.
const char* openNewEdges(const std::vector<std::array<std::uint32_t, 3>>& tris, std::uint32_t firstCreated);

} // namespace rubble::detail::clip
