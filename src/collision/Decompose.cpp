// Approximate convex decomposition by recursive plane cuts (the idea of CoACD, simplified for speed).
//
// Every part is a convex region R (an enlarged bounding box cut by planes) and its convex shape is the exact
// hull of (solid ∩ R): the hull of the mesh triangles clipped to R plus R's corners inside the solid. Regions
// partition space, so parts never overlap and together cover the solid. The part whose surface lies deepest
// inside its hull (what partConcavity measures) is split next, by the candidate plane (axis and
// principal-axis planes through that surface point) that gives the smallest total hull volume; when that
// split removes less than half the volume that the split through the deepest ray pocket (rays cast inward
// from hull faces) of the part deepest by that measure removes, the latter is taken. Until
// params.maxParts or every part is within params.concavity · diagonal of the mesh by both measures.
//
// A mesh above params.proxyAboveTriangles is searched through a bounded proxy (its vertices clustered on a
// grid): the regions come from the proxy, and each part is then the bounded hull of the exact mesh inside
// its region, so the cost of the search does not grow with the triangle count and parts still cover the
// solid (docs/megamesh.md).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <tuple>

#include "collision/HullPlaneTree.hpp"
#include "collision/HullWitness.hpp"
#include "collision/MeshRegion.hpp"
#include "collision/PolygonBvh.hpp"
#include "geometry/OrientedShells.hpp"
#include "rubble/collision/CollisionTolerance.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/DecomposeControl.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

namespace rubble {

namespace {

using detail::Polygon;

struct Part {
    ConvexPolytope region;
    std::vector<Polygon> surface; // mesh triangles clipped to region
    std::vector<Vec3> points;     // the surface's corners, each once, sorted as pointLess orders them
    ConvexPolytope hull;
    double depth = 0;        // deepest pocket between hull and mesh
    Vec3 pocket;             // where that pocket's bottom is
    Vec3 pocketDir;          // inward hull normal there
    double surfaceDepth = 0; // deepest surface sample below the hull's boundary (what partConcavity measures)
    Vec3 surfacePocket;      // that sample
    Vec3 surfaceDir;         // inward normal of the hull face nearest it
    std::vector<Vec3> exactSamples; // through a proxy: the exact mesh's vertices in region
};

/// Cells of the proxy grid along each axis of the bounding box (a finer grid is tried once when the proxy's
/// volume is off by more than kProxyVolumeError).
constexpr int kProxyCells = 16;
constexpr double kProxyVolumeError = 0.25;
/// A pocket shallower than this fraction of the diagonal is rounding, not concavity (a convex mesh is one
/// part even at concavity 0).
constexpr double kFlatDepth = 1e-9;
/// Hull faces whose depth is sampled per part when searching a proxy.
constexpr std::size_t kProxyDepthFaces = 64;
/// Hull faces per job when measuring pocket depth.
constexpr std::size_t kDepthChunk = 32;
/// Share of the progress that the search for cuts takes (the final part shapes take the rest).
constexpr double kSearchShare = 0.9;
/// Most points per side in the hull that bounds a candidate split's score from below.
constexpr std::size_t kBoundPoints = 256;
/// The surface pocket's split wins unless it removes less than this share of the ray pocket's hull volume.
constexpr double kGainShare = 0.5;
/// Concavity below this fraction of the diagonal is rounding: such a part is convex.
constexpr double kConvexTolerance = 1e-9;

/// The order in which hullOfPolygons sorts a hull's input points.
bool pointLess(const Vec3& a, const Vec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}

/// Sorts points[sorted, end) and merges them into the sorted points[0, sorted); each point kept once.
void mergeUnique(std::vector<Vec3>& points, std::size_t sorted) {
    std::sort(points.begin() + static_cast<std::ptrdiff_t>(sorted), points.end(), pointLess);
    std::inplace_merge(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(sorted), points.end(),
                       pointLess);
    points.erase(std::unique(points.begin(), points.end()), points.end());
}

/// The volume of the hull of every k-th point, at most `most` of them (0 when flat or too few): a lower bound
/// of the volume of the points' hull.
double subsetVolume(const std::vector<Vec3>& points, std::size_t most) {
    const std::size_t stride = (points.size() + most - 1) / most;
    std::vector<Vec3> subset;
    subset.reserve(most);
    for (std::size_t i = 0; i < points.size(); i += stride)
        subset.push_back(points[i]);
    return detail::hullVolume(subset);
}

/// Calls f(polygon, inner part, outer part) for each polygon with corners strictly on both sides of the
/// plane.
template <class F>
void forEachCrossed(const std::vector<Polygon>& polygons, const Plane& plane, F&& f) {
    Polygon a, b;
    for (const Polygon& poly : polygons) {
        bool below = false, above = false;
        for (const Vec3& p : poly) {
            const double d = plane.signedDistance(p);
            below |= d < 0;
            above |= d > 0;
        }
        if (!below || !above)
            continue;
        detail::splitPolygon(poly, plane, a, b);
        f(poly, a, b);
    }
}

/// The polygons' corners, each once, sorted.
std::vector<Vec3> cornersOf(const std::vector<Polygon>& polygons) {
    std::vector<Vec3> points;
    for (const Polygon& poly : polygons)
        points.insert(points.end(), poly.begin(), poly.end());
    mergeUnique(points, 0);
    return points;
}

class Decomposer {
public:
    /// mesh: what the regions are searched on; exact: the mesh the parts must cover (mesh or its proxy's
    /// original).
    Decomposer(const Mesh& mesh, const Mesh& exact, const DecompositionParams& params,
               const DecomposeControl& control)
        : mesh_(mesh), exact_(exact), params_(params), control_(control) {
        diag_ = mesh.bounds().diagonal();
    }

    /// True once the caller asked to stop (its flag or its progress callback).
    bool stopped() const {
        return refused_ || (control_.cancel && control_.cancel->load(std::memory_order_relaxed));
    }

    /// Reports progress (never less than before); a callback that returns false cancels.
    void report(double fraction) {
        if (!(fraction > reported_))
            return;
        reported_ = std::min(fraction, 1.0);
        if (control_.progress && !control_.progress(reported_))
            refused_ = true;
    }

    /// Runs task(i) for every i < n, on the calling thread and the control's job system; returns when all
    /// are done. Helper jobs that start after the calling thread ran out of work do nothing, so busy workers
    /// (or the very pool the caller runs on) never make it wait.
    void parallelFor(std::size_t n, const std::function<void(std::size_t)>& task) {
        const int helpers =
            control_.jobs ? std::min(control_.jobs->workerCount(), static_cast<int>(n) - 1) : 0;
        if (helpers <= 0) {
            for (std::size_t i = 0; i < n; ++i)
                task(i);
            return;
        }
        struct Shared {
            std::atomic<std::size_t> next{0};
            std::mutex mutex;
            std::condition_variable idle;
            int active = 0;      // helpers running tasks
            bool closed = false; // the caller is done: late helpers return at once
        };
        const auto shared = std::make_shared<Shared>();
        const std::function<void(std::size_t)>* work = &task; // used only by active helpers
        for (int h = 0; h < helpers; ++h)
            control_.jobs->submit([shared, work, n] {
                {
                    const std::lock_guard lock(shared->mutex);
                    if (shared->closed)
                        return;
                    ++shared->active;
                }
                for (std::size_t i = shared->next++; i < n; i = shared->next++)
                    (*work)(i);
                const std::lock_guard lock(shared->mutex);
                if (--shared->active == 0)
                    shared->idle.notify_all();
            });
        for (std::size_t i = shared->next++; i < n; i = shared->next++)
            task(i);
        std::unique_lock lock(shared->mutex);
        shared->closed = true;
        shared->idle.wait(lock, [&] { return shared->active == 0; });
    }

    bool proxied() const { return &mesh_ != &exact_; }

    /// Inside the exact mesh: the proxy's winding number decides away from the surface, the exact mesh's
    /// near it.
    bool insideExact(const Vec3& p) {
        if (!proxied())
            return inside(p);
        const double w = windingNumber(mesh_, p);
        if (w < 0.2 || w > 0.8)
            return w > 0.5;
        return detail::insideMesh(exact_, p);
    }

    /// The final shape of a part: its hull, or with a proxy the bounded hull of the exact mesh in its region;
    /// either bounded to params.maxPartFaces faces.
    std::optional<ConvexPolytope> finalShape(Part& part) {
        if (!proxied()) {
            if (part.hull.faces().size() <= params_.maxPartFaces)
                return std::move(part.hull);
            auto b = boundedHull(part.hull.vertices(), params_.maxPartFaces);
            return b ? std::optional<ConvexPolytope>(std::move(b.value())) : std::move(part.hull);
        }
        std::vector<Vec3> points = exactPointsIn(part.region);
        for (const Vec3& v : part.region.vertices())
            if (insideExact(v))
                points.push_back(v);
        auto b = boundedHull(points, params_.maxPartFaces);
        if (!b)
            return std::nullopt;
        return std::move(b.value());
    }

    /// The exact mesh's surface points in a region, each vertex once: the vertices inside it and the corners
    /// of the triangles that cross its boundary, clipped to it.
    std::vector<Vec3> exactPointsIn(const ConvexPolytope& region) const {
        const Aabb rb = region.bounds();
        std::vector<std::uint8_t> in(exact_.positions.size(), 0);
        std::vector<Vec3> points;
        for (std::size_t v = 0; v < exact_.positions.size(); ++v)
            if (rb.contains(exact_.positions[v]) && region.contains(exact_.positions[v])) {
                in[v] = 1;
                points.push_back(exact_.positions[v]);
            }
        detail::Polygon poly, inner, outer;
        for (std::size_t t = 0; t < exact_.triangles.size(); ++t) {
            const Triangle& tri = exact_.triangles[t];
            if (in[tri[0]] && in[tri[1]] && in[tri[2]])
                continue;
            const auto c = exact_.corners(t);
            Aabb tb;
            for (const Vec3& p : c)
                tb.extend(p);
            if (!tb.overlaps(rb))
                continue;
            poly.assign(c.begin(), c.end());
            for (const PolytopeFaceView& f : region.faces()) {
                detail::splitPolygon(poly, f.plane, inner, outer);
                poly.swap(inner);
                if (poly.size() < 3)
                    break;
            }
            if (poly.size() >= 3)
                points.insert(points.end(), poly.begin(), poly.end());
        }
        return points;
    }

    bool inside(const Vec3& p) {
        auto key = std::make_tuple(p.x, p.y, p.z);
        {
            const std::lock_guard lock(insideMutex_);
            auto it = insideCache_.find(key);
            if (it != insideCache_.end())
                return it->second;
        }
        // The signed crossings of a ray through the mesh's tree; the winding number's sum where the ray
        // passes near an edge or p lies on the surface.
        std::call_once(meshTreeOnce_, [this] { meshTree_ = std::make_unique<detail::PolygonBvh>(mesh_); });
        const Vec3 ray = normalized(Vec3{0.3141592653589793, 0.5772156649015329, 0.7071067811865476});
        const std::optional<int> w = meshTree_->winding(p, ray, 1e-9 * std::max(diag_, 1e-300));
        const bool in = w ? *w > 0 : detail::insideMesh(mesh_, p);
        const std::lock_guard lock(insideMutex_);
        insideCache_.emplace(key, in);
        return in;
    }

    /// The hull of a part: of its surface's corners (sorted, each once) and its region's corners inside the
    /// solid, the input hullOfPolygons would give Qhull; nullopt without a surface and 4 such corners.
    std::optional<ConvexPolytope> hullOf(const std::vector<Vec3>& surfacePoints,
                                         const ConvexPolytope& region) {
        std::vector<Vec3> points = surfacePoints;
        for (const Vec3& v : region.vertices())
            if (inside(v))
                points.push_back(v);
        if (surfacePoints.empty() && points.size() < 4)
            return std::nullopt;
        mergeUnique(points, surfacePoints.size());
        auto h = convexHull(points);
        if (!h)
            return std::nullopt;
        return std::move(h.value());
    }

    /// Deepest pocket between the hull and the surface, from rays cast inward at samples of hull faces that
    /// do not lie on a cut plane of the region. Chunks of faces run through parallelFor; each keeps its first
    /// deepest sample and the chunks are compared in order, as one pass over the faces would.
    void measureDepth(Part& part) {
        part.depth = 0;
        std::vector<Plane> cuts;
        for (const PolytopeFaceView& f : part.region.faces())
            if (f.tag >= 0)
                cuts.push_back(f.plane);
        // Through a proxy, only the kProxyDepthFaces largest hull faces are sampled (pockets lie under large
        // faces that bridge them).
        const PolytopeFaces hullFaces = part.hull.faces();
        std::vector<std::size_t> order(hullFaces.size());
        for (std::size_t i = 0; i < order.size(); ++i)
            order[i] = i;
        if (proxied() && order.size() > kProxyDepthFaces) {
            std::vector<double> area(hullFaces.size(), 0);
            for (std::size_t i = 0; i < hullFaces.size(); ++i) {
                const PolytopeCorners c = hullFaces[i].corners;
                for (std::size_t k = 1; k + 1 < c.size(); ++k)
                    area[i] += length(cross(c[k] - c[0], c[k + 1] - c[0]));
            }
            std::partial_sort(order.begin(), order.begin() + kProxyDepthFaces, order.end(),
                              [&](std::size_t a, std::size_t b) {
                                  return area[a] > area[b] || (area[a] == area[b] && a < b);
                              });
            order.resize(kProxyDepthFaces);
        }
        const detail::PolygonBvh bvh(part.surface);
        std::vector<Plane> planes;
        planes.reserve(hullFaces.size());
        for (const PolytopeFaceView& f : hullFaces)
            planes.push_back(f.plane);
        const detail::HullPlaneTree exitTree(hullFaces, planes);
        // The hull's box, padded: a ray leaves it no earlier than it leaves the hull.
        Aabb hullBox = part.hull.bounds();
        const double boxPad = 1e-6 * (hullBox.diagonal() + diag_) + 1e-300;
        hullBox.lo -= Vec3{boxPad, boxPad, boxPad};
        hullBox.hi += Vec3{boxPad, boxPad, boxPad};
        const std::size_t chunks = (order.size() + kDepthChunk - 1) / kDepthChunk;
        std::vector<Deepest> deepest(chunks);
        parallelFor(chunks, [&](std::size_t chunk) {
            const std::size_t end = std::min(order.size(), (chunk + 1) * kDepthChunk);
            for (std::size_t k = chunk * kDepthChunk; k < end; ++k)
                faceDepth(hullFaces[order[k]], planes, exitTree, cuts, bvh, hullBox, deepest[chunk]);
        });
        for (const Deepest& d : deepest)
            if (d.depth > part.depth) {
                part.depth = d.depth;
                part.pocket = d.pocket;
                part.pocketDir = d.dir;
            }
    }

    /// The surface sample (corners, polygon centres, exact vertices) deepest inside the part's hull.
    static void measureSurfaceDepth(Part& part) {
        part.surfaceDepth = 0;
        const PolytopeFaces faces = part.hull.faces();
        std::vector<Plane> planes;
        planes.reserve(faces.size());
        for (const PolytopeFaceView& f : faces)
            planes.push_back(f.plane);
        auto visit = [&](const Vec3& p) {
            double d = std::numeric_limits<double>::infinity();
            std::size_t nearest = 0;
            for (std::size_t k = 0; k < planes.size(); ++k) {
                const double s = -planes[k].signedDistance(p);
                if (s < d) {
                    d = s;
                    nearest = k;
                    if (d <= part.surfaceDepth)
                        return; // cannot be deeper than the deepest so far
                }
            }
            if (d > part.surfaceDepth && !planes.empty()) {
                part.surfaceDepth = d;
                part.surfacePocket = p;
                part.surfaceDir = -planes[nearest].normal;
            }
        };
        for (const Polygon& poly : part.surface) {
            Vec3 g;
            for (const Vec3& c : poly)
                g += c;
            visit(g / static_cast<double>(poly.size()));
        }
        for (const Vec3& p : part.points)
            visit(p);
        for (const Vec3& p : part.exactSamples)
            visit(p);
    }

    /// A pocket's depth, bottom and ray direction.
    struct Deepest {
        double depth = 0;
        Vec3 pocket, dir;
    };

    /// The deepest pocket under the samples of one hull face, where deeper than `best` so far.
    void faceDepth(const PolytopeFaceView& hf, const std::vector<Plane>& planes,
                   const detail::HullPlaneTree& exitTree, const std::vector<Plane>& cuts,
                   const detail::PolygonBvh& bvh, const Aabb& box, Deepest& best) const {
        const double delta = 1e-9 * std::max(diag_, 1.0);
        const double planeTol = 1e-7 * std::max(diag_, 1.0);
        bool onCut = false;
        for (const Plane& c : cuts)
            if (dot(c.normal, hf.plane.normal) > 1 - 1e-9 && std::abs(c.offset - hf.plane.offset) < planeTol)
                onCut = true;
        if (onCut)
            return;
        Vec3 g;
        for (const Vec3& c : hf.corners)
            g += c;
        g = g / static_cast<double>(hf.corners.size());
        std::vector<Vec3> samples;
        samples.push_back(g);
        const std::size_t n = hf.corners.size();
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3& a = hf.corners[i];
            const Vec3& b = hf.corners[(i + 1) % n];
            samples.push_back(g + (a - g) * 0.6);
            samples.push_back(g + ((a + b) * 0.5 - g) * 0.6);
        }
        const Vec3 dir = -hf.plane.normal;
        const double stop = delta * 2;
        for (const Vec3& s : samples) {
            const Vec3 o = s + hf.plane.normal * delta;
            const double t = depthAlong(o, dir, planes, exitTree, box, stop, bvh);
            const double depth = t - delta;
            if (depth > best.depth) {
                best.depth = depth;
                best.pocket = o + dir * t;
                best.dir = dir;
            }
        }
    }

    /// min(first surface hit, exit from the hull) along o + t·dir, as bvh.nearest(o, dir, exit, stop) gives
    /// it; planes are the hull's. The hit is found first, bounded by the exit from box (which holds the
    /// hull), so that only the planes the ray may leave through before it are divided out (found through
    /// exitTree).
    static double depthAlong(const Vec3& o, const Vec3& dir, const std::vector<Plane>& planes,
                             const detail::HullPlaneTree& exitTree, const Aabb& box, double stop,
                             const detail::PolygonBvh& bvh) {
        auto exactExit = [&] {
            double tExit = std::numeric_limits<double>::infinity();
            for (const Plane& plane : planes)
                if (const double nd = dot(plane.normal, dir); nd > 1e-12)
                    tExit = std::min(tExit, (plane.offset - dot(plane.normal, o)) / nd);
            return tExit;
        };
        double boxExit = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 3; ++a)
            if (dir[a] != 0)
                boxExit = std::min(boxExit, ((dir[a] > 0 ? box.hi[a] : box.lo[a]) - o[a]) / dir[a]);
        if (!(boxExit > stop) || !std::isfinite(boxExit))
            return bvh.nearest(o, dir, exactExit(), stop);
        const double hit = bvh.nearest(o, dir, boxExit, stop);
        // Planes left through before max(hit, stop) (with room for rounding); the others exit later.
        const double tExit = exitTree.exitBefore(o, dir, std::max(hit, stop) * (1 + 1e-9));
        if (!(tExit > stop)) // leaves at once: the search stops at its first leaf, as before
            return bvh.nearest(o, dir, exactExit(), stop);
        return std::min(hit, tExit);
    }

    /// Two parts and their score; the parts' surfaces are filled in by surfaceSplit, for the chosen split.
    struct Split {
        double score = std::numeric_limits<double>::infinity();
        Plane plane;
        Part left, right;
        bool surfaced = false; // left.surface and right.surface are filled in
    };

    /// Split's parts from their regions and surface points; nullopt when a side has no hull or too little
    /// volume, or when the score exceeds cutoff (the side with fewer points is made first: with the other
    /// side's lower bound, bounds[1] for the outer side and bounds[0] for the inner, it may lose already).
    std::optional<Split> makeSplit(const Part& part, const Plane& plane, ConvexPolytope rin,
                                   ConvexPolytope rout, std::vector<Vec3> pin, std::vector<Vec3> pout,
                                   double cutoff, const std::array<double, 2>& bounds) {
        const bool inFirst = pin.size() <= pout.size();
        std::optional<ConvexPolytope> l, r;
        for (int k = 0; k < 2; ++k) {
            const bool in = (k == 0) == inFirst;
            std::optional<ConvexPolytope>& h = in ? l : r;
            h = in ? hullOf(pin, rin) : hullOf(pout, rout);
            if (!h)
                return std::nullopt;
            if (k == 0 && h->volume() + bounds[in ? 1 : 0] > cutoff)
                return std::nullopt;
        }
        const double minVol = std::max(1e-9 * part.hull.volume(), minPartVolume_);
        if (l->volume() < minVol || r->volume() < minVol)
            return std::nullopt;
        Split s;
        s.score = l->volume() + r->volume();
        s.plane = plane;
        s.left.region = std::move(rin);
        s.left.points = std::move(pin);
        s.left.hull = std::move(*l);
        s.right.region = std::move(rout);
        s.right.points = std::move(pout);
        s.right.hull = std::move(*r);
        return s;
    }

    /// The part's surface split by the plane, into the inner and the outer polygons.
    static void splitSurface(const Part& part, const Plane& plane, std::vector<Polygon>& sin,
                             std::vector<Polygon>& sout) {
        Polygon a, b;
        for (const Polygon& poly : part.surface) {
            detail::splitPolygon(poly, plane, a, b);
            if (a.size() >= 3)
                sin.push_back(a);
            if (b.size() >= 3)
                sout.push_back(b);
        }
    }

    /// Fills in the surfaces of a split of part.
    static void surfaceSplit(const Part& part, Split& s) {
        if (!s.surfaced)
            splitSurface(part, s.plane, s.left.surface, s.right.surface);
        s.surfaced = true;
    }

    /// The split of a part by a plane: its two sides' hulls and score (nullopt past cutoff, see makeSplit).
    /// Each side's points are the part's points on that side and the corners the plane makes on the polygons
    /// it crosses, which are the corners of the side's polygons; where a point lies on the plane, the
    /// polygons are split to decide.
    std::optional<Split> trySplit(const Part& part, const Plane& plane, double cutoff,
                                  const std::array<double, 2>& bounds) {
        ConvexPolytope rin = part.region.clipped(plane, nextTag_);
        ConvexPolytope rout = part.region.clippedOutside(plane, nextTag_);
        if (rin.empty() || rout.empty())
            return std::nullopt;
        std::vector<Vec3> pin, pout;
        bool onPlane = false;
        for (const Vec3& p : part.points) {
            const double d = plane.signedDistance(p);
            if (d < 0)
                pin.push_back(p);
            else if (d > 0)
                pout.push_back(p);
            else
                onPlane = true;
        }
        if (onPlane) {
            Split s;
            splitSurface(part, plane, s.left.surface, s.right.surface);
            auto made = makeSplit(part, plane, std::move(rin), std::move(rout), cornersOf(s.left.surface),
                                  cornersOf(s.right.surface), cutoff, bounds);
            if (made) {
                made->left.surface = std::move(s.left.surface);
                made->right.surface = std::move(s.right.surface);
                made->surfaced = true;
            }
            return made;
        }
        const std::size_t sortedIn = pin.size(), sortedOut = pout.size();
        forEachCrossed(part.surface, plane, [&](const Polygon&, const Polygon& a, const Polygon& b) {
            pin.insert(pin.end(), a.begin(), a.end());
            pout.insert(pout.end(), b.begin(), b.end());
        });
        mergeUnique(pin, sortedIn);
        mergeUnique(pout, sortedOut);
        return makeSplit(part, plane, std::move(rin), std::move(rout), std::move(pin), std::move(pout),
                         cutoff, bounds);
    }

    /// Lower bounds of the volumes of trySplit(part, plane)'s inner and outer sides, whose sum bounds its
    /// score: the volumes of the hulls, on each side, of the part's hull vertices there and the points where
    /// the surface crosses the plane (all of them points that the side's own hull holds; a side with too few
    /// or flat points counts 0).
    std::array<double, 2> splitBound(const Part& part, const std::vector<Vec3>& hullVertices,
                                     const Plane& plane) const {
        std::vector<Vec3> in, out;
        const double tol = 1e-12 * std::max(diag_, 1e-300);
        for (const Vec3& v : hullVertices) {
            const double d = plane.signedDistance(v);
            if (d < -tol)
                in.push_back(v);
            else if (d > tol)
                out.push_back(v);
        }
        // The corners the split makes on the plane, as trySplit makes them.
        forEachCrossed(part.surface, plane, [&](const Polygon& poly, const Polygon& a, const Polygon& b) {
            for (const Vec3& p : a)
                if (std::find(poly.begin(), poly.end(), p) == poly.end())
                    in.push_back(p);
            for (const Vec3& p : b)
                if (std::find(poly.begin(), poly.end(), p) == poly.end())
                    out.push_back(p);
        });
        // Every k-th point, at most kBoundPoints: a subset's hull is a lower bound too, and far cheaper.
        return {subsetVolume(in, kBoundPoints), subsetVolume(out, kBoundPoints)};
    }

    /// The split of part by a plane through `at` (one of its pockets) with the least score (the first of
    /// equal scores), as evaluating every candidate would find it. Candidates are tried in the order of a
    /// lower bound of their score, a batch at a time on the job system, and those whose bound already loses
    /// are skipped (hullVertices: part.hull.vertices()); nullopt too when no score is below `beat`.
    std::optional<Split> bestSplit(const Part& part, const std::vector<Vec3>& hullVertices,
                                   const std::vector<Vec3>& normals, const Vec3& at,
                                   double beat = std::numeric_limits<double>::infinity()) {
        const std::size_t n = normals.size();
        std::vector<double> bound(n, 0);
        std::vector<std::array<double, 2>> sides(n, {0, 0});
        parallelFor(n, [&](std::size_t i) {
            if (!stopped()) {
                sides[i] = splitBound(part, hullVertices, Plane::fromPointNormal(at, normals[i]));
                bound[i] = sides[i][0] + sides[i][1];
            }
        });
        std::vector<std::size_t> order(n);
        for (std::size_t i = 0; i < n; ++i)
            order[i] = i;
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return bound[a] < bound[b]; });
        std::optional<Split> chosen;
        std::size_t chosenIndex = n;
        // A candidate can still win while its bound does not exceed the best score (with room for the
        // rounding of two hulls' volumes: a bound may equal a score).
        auto best = [&] { return std::min(chosen ? chosen->score : beat, beat) * (1 + 1e-9); };
        auto mayWin = [&](std::size_t i) { return bound[i] <= best(); };
        const std::size_t batch =
            control_.jobs ? static_cast<std::size_t>(std::max(1, control_.jobs->workerCount()) + 1) : 1;
        for (std::size_t next = 0; next < n && !stopped();) {
            std::vector<std::size_t> take;
            for (; next < n && take.size() < batch; ++next)
                if (mayWin(order[next]))
                    take.push_back(order[next]);
            std::vector<std::optional<Split>> tries(take.size());
            const double cutoff = best();
            parallelFor(take.size(), [&](std::size_t k) {
                if (!stopped())
                    tries[k] =
                        trySplit(part, Plane::fromPointNormal(at, normals[take[k]]), cutoff, sides[take[k]]);
            });
            for (std::size_t k = 0; k < take.size(); ++k)
                if (tries[k] && (!chosen || tries[k]->score < chosen->score ||
                                 (tries[k]->score == chosen->score && take[k] < chosenIndex))) {
                    chosen = std::move(tries[k]);
                    chosenIndex = take[k];
                }
        }
        return chosen;
    }

    std::vector<Vec3> candidateNormals(const std::vector<Vec3>& v, const Vec3& pocketDir) const {
        std::vector<Vec3> normals = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        // Principal axes of the hull's vertices.
        Vec3 mean;
        for (const Vec3& p : v)
            mean += p;
        mean = mean / static_cast<double>(v.size());
        Mat3 cov;
        for (const Vec3& p : v) {
            const Vec3 d = p - mean;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    cov.m[i][j] += d[i] * d[j];
        }
        // Jacobi iterations for the eigenvectors.
        Mat3 axes = Mat3::identity();
        for (int sweep = 0; sweep < 12; ++sweep)
            for (int p = 0; p < 2; ++p)
                for (int q = p + 1; q < 3; ++q) {
                    if (std::abs(cov.m[p][q]) < 1e-15)
                        continue;
                    const double theta = 0.5 * std::atan2(2 * cov.m[p][q], cov.m[q][q] - cov.m[p][p]);
                    const double c = std::cos(theta), s = std::sin(theta);
                    Mat3 r = Mat3::identity();
                    r.m[p][p] = c;
                    r.m[q][q] = c;
                    r.m[p][q] = s;
                    r.m[q][p] = -s;
                    cov = r.transposed() * cov * r;
                    axes = axes * r;
                }
        for (int j = 0; j < 3; ++j) {
            const Vec3 a = normalized(axes.column(j));
            bool dup = false;
            for (const Vec3& n : normals)
                dup |= std::abs(dot(n, a)) > 0.999;
            if (!dup && lengthSquared(a) > 0.5)
                normals.push_back(a);
        }
        // Axes perpendicular to the pocket direction.
        const std::size_t base = normals.size();
        for (std::size_t i = 0; i < base; ++i) {
            const Vec3 n = normalized(normals[i] - pocketDir * dot(normals[i], pocketDir));
            bool dup = lengthSquared(n) < 0.5;
            for (const Vec3& m : normals)
                dup |= std::abs(dot(n, m)) > 0.999;
            if (!dup)
                normals.push_back(n);
        }
        return normals;
    }

    Result<Decomposition> run() {
        auto out = search();
        if (stopped())
            return makeError(ErrorCode::Cancelled, "decompose: cancelled");
        if (out)
            report(1);
        return out;
    }

    Result<Decomposition> search() {
        Decomposition out;
        out.meshVolume = signedVolume(exact_);
        const double searchVolume = proxied() ? signedVolume(mesh_) : out.meshVolume;
        if (exact_.empty() || !(out.meshVolume > 0) || mesh_.triangles.size() < 4 || !(searchVolume > 0))
            return makeError(ErrorCode::InvalidInput,
                             "decompose: the mesh must be closed with positive volume (volume " +
                                 std::to_string(out.meshVolume) + ")");
        Aabb box = mesh_.bounds();
        box.extend(exact_.bounds());
        const Vec3 pad = Vec3{1, 1, 1} * (0.01 * diag_ + 1e-9);
        box.lo -= pad;
        box.hi += pad;
        auto hull = convexHull(mesh_.positions);
        if (!hull)
            return hull.error();
        double area = 0;
        for (const PolytopeFaceView& f : hull->faces())
            for (std::size_t i = 1; i + 1 < f.corners.size(); ++i)
                area += 0.5 * length(cross(f.corners[i] - f.corners[0], f.corners[i + 1] - f.corners[0]));
        // A part convex to within kConvexTolerance of the diagonal is not split (rounding is not concavity).
        const double threshold = std::max(params_.concavity, kConvexTolerance) * diag_;
        minPartVolume_ = params_.minPartVolumeFraction * out.meshVolume;
        if (params_.maxParts <= 1 ||
            hull->volume() - searchVolume <= std::max(0.01 * threshold, kFlatDepth * diag_) * area) {
            Part whole;
            whole.region = ConvexPolytope::fromAabb(box);
            whole.hull = std::move(hull.value());
            auto shape = finalShape(whole);
            if (!shape)
                return makeError(ErrorCode::InvalidInput, "decompose: the mesh is flat");
            out.hullVolume = shape->volume();
            out.parts.push_back(std::move(*shape));
            return out;
        }
        std::vector<Polygon> surface;
        surface.reserve(mesh_.triangles.size());
        for (std::size_t t = 0; t < mesh_.triangles.size(); ++t) {
            const auto c = mesh_.corners(t);
            surface.push_back({c[0], c[1], c[2]});
        }
        std::vector<Part> parts;
        {
            Part root;
            root.region = ConvexPolytope::fromAabb(box);
            root.surface = std::move(surface);
            root.points = cornersOf(root.surface);
            root.hull = std::move(hull.value());
            if (proxied())
                root.exactSamples = exact_.positions;
            measureDepth(root);
            measureSurfaceDepth(root);
            parts.push_back(std::move(root));
        }
        // Per part and pocket kind (0: surface depth, 1: ray depth), its best split once tried.
        struct Pending {
            bool tried = false;
            std::optional<Split> split;
            double gain = 0; // hull volume the split removes
        };
        std::vector<std::array<Pending, 2>> pending(1);
        // A search under a finite `beat` that finds nothing is not kept: it says only that nothing beat it.
        auto splitOf = [&](std::size_t i, int kind, double beat) -> Pending& {
            Pending& p = pending[i][kind];
            if (p.tried)
                return p;
            const Part& part = parts[i];
            const std::vector<Vec3> hullVertices = part.hull.vertices();
            const std::vector<Vec3> normals =
                candidateNormals(hullVertices, kind == 0 ? part.surfaceDir : part.pocketDir);
            p.split =
                bestSplit(part, hullVertices, normals, kind == 0 ? part.surfacePocket : part.pocket, beat);
            ++nextTag_;
            if (p.split && p.split->score > part.hull.volume() * (1 + 1e-9))
                p.split.reset();
            p.tried = p.split || !std::isfinite(beat);
            if (p.split)
                p.gain = part.hull.volume() - p.split->score;
            return p;
        };
        const double limit = std::max(threshold, kFlatDepth * diag_);
        while (static_cast<int>(parts.size()) < params_.maxParts) {
            if (stopped())
                return out;
            // The part deepest by each measure whose split of that kind is not known to fail.
            std::array<int, 2> best = {-1, -1};
            for (std::size_t i = 0; i < parts.size(); ++i)
                for (int kind = 0; kind < 2; ++kind) {
                    const auto depthOf = [&](std::size_t j) {
                        return kind == 0 ? parts[j].surfaceDepth : parts[j].depth;
                    };
                    const Pending& p = pending[i][kind];
                    if (!(p.tried && !p.split) && depthOf(i) > limit &&
                        (best[kind] < 0 || depthOf(i) > depthOf(static_cast<std::size_t>(best[kind]))))
                        best[kind] = static_cast<int>(i);
                }
            if (best[0] < 0 && best[1] < 0)
                break;
            // The search is done when the parts reach the budget or the deepest pockets the threshold.
            double deepest = 0;
            if (best[0] >= 0)
                deepest = parts[best[0]].surfaceDepth;
            if (best[1] >= 0)
                deepest = std::max(deepest, parts[best[1]].depth);
            report(kSearchShare *
                   std::max(static_cast<double>(parts.size()) / params_.maxParts, threshold / deepest));
            // The surface pocket's split, unless the ray pocket's removes more than 1 / kGainShare times as
            // much hull volume (searched only for scores that would).
            const double inf = std::numeric_limits<double>::infinity();
            std::array<Pending*, 2> tries = {nullptr, nullptr};
            if (best[0] >= 0 && !(tries[0] = &splitOf(static_cast<std::size_t>(best[0]), 0, inf))->split)
                continue; // no split: known to fail now
            if (best[1] >= 0) {
                const std::size_t b = static_cast<std::size_t>(best[1]);
                const double beat = tries[0] ? parts[b].hull.volume() - tries[0]->gain / kGainShare : inf;
                if (beat > 0) {
                    tries[1] = &splitOf(b, 1, beat);
                    if (!tries[1]->split && tries[1]->tried)
                        continue;
                    if (!tries[1]->split)
                        tries[1] = nullptr;
                }
            }
            if (stopped())
                continue;
            const int kind = tries[0] && (!tries[1] || tries[0]->gain >= kGainShare * tries[1]->gain) ? 0 : 1;
            const std::size_t at = static_cast<std::size_t>(best[kind]);
            Split chosen = std::move(*tries[kind]->split);
            surfaceSplit(parts[at], chosen);
            for (const Vec3& p : parts[at].exactSamples)
                (chosen.plane.signedDistance(p) < 0 ? chosen.left : chosen.right).exactSamples.push_back(p);
            for (Part* side : {&chosen.left, &chosen.right}) {
                measureDepth(*side);
                measureSurfaceDepth(*side);
            }
            parts[at] = std::move(chosen.left);
            pending[at] = {};
            parts.push_back(std::move(chosen.right));
            pending.emplace_back();
        }
        report(kSearchShare);
        const double minVol = params_.minPartVolumeFraction * out.meshVolume;
        std::vector<std::optional<ConvexPolytope>> shapes(parts.size());
        parallelFor(parts.size(), [&](std::size_t i) {
            if (!stopped() && !(parts[i].hull.volume() < minVol && parts.size() > 1))
                shapes[i] = finalShape(parts[i]);
        });
        if (stopped())
            return out;
        for (std::optional<ConvexPolytope>& shape : shapes)
            if (shape)
                out.parts.push_back(std::move(*shape));
        // Through a proxy, each part's corners are proven near the exact mesh's hull, as a high-poly piece's
        // are after a fracture (bounded hulls of many points reach out by their pushed-out planes).
        if (proxied())
            detail::keepNearHull(out.parts, exact_,
                                 detail::kHullReachShare * partHullTolerance(exact_.bounds().diagonal()),
                                 params_.maxPartFaces);
        for (const ConvexPolytope& part : out.parts)
            out.hullVolume += part.volume();
        if (out.parts.empty())
            return makeError(ErrorCode::GeometryFailure, "decompose: no part holds any of the mesh");
        return out;
    }

private:
    const Mesh& mesh_;
    const Mesh& exact_;
    DecompositionParams params_;
    const DecomposeControl& control_;
    double reported_ = 0;  // progress reported so far
    bool refused_ = false; // the progress callback asked to stop
    std::mutex insideMutex_;
    double diag_ = 0;
    std::int32_t nextTag_ = 0;
    double minPartVolume_ = 0;
    std::map<std::tuple<double, double, double>, bool> insideCache_;
    std::once_flag meshTreeOnce_;
    std::unique_ptr<detail::PolygonBvh> meshTree_; // mesh_'s triangles, for inside()
};

} // namespace

Status checkDecompositionParams(const DecompositionParams& params) {
    auto bad = [](const std::string& what) { return makeError(ErrorCode::InvalidInput, what); };
    if (params.maxParts < 1 || params.maxParts > kMaxConvexParts)
        return bad("maxParts " + std::to_string(params.maxParts) + " is outside [1, " +
                   std::to_string(kMaxConvexParts) + "]");
    if (!(params.concavity >= 0 && params.concavity < 1e300))
        return bad("concavity " + std::to_string(params.concavity) + " is not a finite number >= 0");
    if (!(params.minPartVolumeFraction >= 0 && params.minPartVolumeFraction <= 1))
        return bad("minPartVolumeFraction " + std::to_string(params.minPartVolumeFraction) +
                   " is outside [0, 1]");
    if (params.maxPartFaces < 4)
        return bad("maxPartFaces " + std::to_string(params.maxPartFaces) + " is below 4");
    return {};
}

Result<Decomposition> decompose(const Mesh& mesh, const DecompositionParams& params) {
    return decompose(mesh, params, DecomposeControl{});
}

Result<Decomposition> decompose(const Mesh& mesh, const DecompositionParams& params,
                                const DecomposeControl& control) {
    if (const Status s = checkDecompositionParams(params); !s)
        return makeError(ErrorCode::InvalidInput, "decompose: " + s.message());
    if (const Status s = mesh.validate(); !s)
        return s.error();
    if (const Status s = checkCoordinateRange(mesh, "decompose"); !s)
        return s.error();
    if (detail::closedOrientedShells(mesh, nullptr) < 0)
        return makeError(ErrorCode::InvalidInput,
                         "decompose: the mesh is not closed and consistently oriented (every edge must be "
                         "shared by exactly two triangles in opposite directions); see rubble check");
    if (mesh.triangles.size() < 4)
        return makeError(ErrorCode::InvalidInput, "decompose: a closed mesh needs at least 4 triangles");
    if (mesh.triangles.size() > params.proxyAboveTriangles) {
        const double volume = signedVolume(mesh);
        for (int cells : {kProxyCells, 2 * kProxyCells}) {
            const Mesh proxy = detail::clusteredProxy(mesh, cells);
            if (std::abs(signedVolume(proxy) - volume) > kProxyVolumeError * std::abs(volume))
                continue; // too coarse for a thin feature: finer, else the exact search
            Decomposer d(proxy, mesh, params, control);
            return d.run();
        }
    }
    Decomposer d(mesh, mesh, params, control);
    return d.run();
}

} // namespace rubble
