// Convex hull of a point set through Qhull's reentrant C API (libqhull_r). Qhull reports errors with
// setjmp/longjmp inside qh_new_qhull and returns an exit code; its messages go to an in-memory stream that
// becomes the error message, so nothing is printed and nothing exits.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <tuple>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include "collision/MeshRegion.hpp"
#include "geometry/PseudoAngle.hpp"
#include "rubble/collision/CollisionTolerance.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"

namespace rubble {

namespace {
/// An in-memory FILE* collecting Qhull's messages.
class MessageStream {
public:
    MessageStream() { file_ = open_memstream(&buffer_, &size_); }
    ~MessageStream() {
        if (file_)
            std::fclose(file_);
        std::free(buffer_);
    }
    MessageStream(const MessageStream&) = delete;
    MessageStream& operator=(const MessageStream&) = delete;
    FILE* file() const { return file_; }
    std::string text() {
        if (!file_)
            return {};
        std::fflush(file_);
        std::string s(buffer_ ? buffer_ : "", size_);
        while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
            s.pop_back();
        if (s.size() > 400)
            s = s.substr(0, 400) + "...";
        return s;
    }

private:
    FILE* file_ = nullptr;
    char* buffer_ = nullptr;
    std::size_t size_ = 0;
};

/// One Qhull run over finite points, freed when destroyed. The options skip the final pass over every point
/// for the outer planes (Q5) and the tracking of near-inside points (Q8): neither changes the facets.
class QhullRun {
public:
    explicit QhullRun(const std::vector<Vec3>& points) {
        coords_.reserve(points.size() * 3);
        for (const Vec3& p : points)
            coords_.insert(coords_.end(), {p.x, p.y, p.z});
        FILE* err = errors_.file() ? errors_.file() : stderr;
        qh_zero(&qh_, err);
        char command[] = "qhull Pp Q5 Q8";
        exitCode_ = qh_new_qhull(&qh_, 3, static_cast<int>(points.size()), coords_.data(), False, command,
                                 nullptr, err);
    }
    ~QhullRun() {
        qh_freeqhull(&qh_, !qh_ALL);
        int curlong = 0, totlong = 0;
        qh_memfreeshort(&qh_, &curlong, &totlong);
    }
    QhullRun(const QhullRun&) = delete;
    QhullRun& operator=(const QhullRun&) = delete;

    bool ok() const { return exitCode_ == 0; }
    qhT* qh() { return &qh_; }
    std::string errorText() { return errors_.text(); }

private:
    MessageStream errors_; // declared first: Qhull may write to it until the destructor's body ends
    std::vector<coordT> coords_;
    qhT qh_;
    int exitCode_ = 0;
};

} // namespace

Result<ConvexPolytope> convexHull(const std::vector<Vec3>& points) {
    if (points.size() < 4)
        return makeError(ErrorCode::InvalidInput,
                         "convex hull needs at least 4 points, got " + std::to_string(points.size()));
    for (const Vec3& p : points)
        if (!isFinite(p))
            return makeError(ErrorCode::InvalidInput, "convex hull: non-finite point");
    QhullRun run(points);
    if (!run.ok()) {
        std::string msg = run.errorText();
        const bool flat = msg.find("QH6154") != std::string::npos || msg.find("flat") != std::string::npos ||
                          msg.find("QH6214") != std::string::npos || msg.find("QH6271") != std::string::npos;
        return makeError(flat ? ErrorCode::InvalidInput : ErrorCode::GeometryFailure,
                         std::string("convex hull: ") +
                             (flat ? "points are coplanar or degenerate" : "Qhull failed") +
                             (msg.empty() ? "" : " (" + msg + ")"));
    }
    qhT* qh = run.qh();
    std::vector<PolytopeFace> faces;
    facetT* facet;
    vertexT* vertex;
    vertexT** vertexp;
    FORALLfacets {
        PolytopeFace f;
        f.plane.normal = {facet->normal[0], facet->normal[1], facet->normal[2]};
        f.plane.offset = -facet->offset;
        Vec3 center;
        FOREACHvertex_(facet->vertices) {
            const Vec3 p{vertex->point[0], vertex->point[1], vertex->point[2]};
            f.corners.push_back(p);
            center += p;
        }
        if (f.corners.size() < 3)
            continue;
        center = center / static_cast<double>(f.corners.size());
        const Vec3 n = f.plane.normal;
        const Vec3 u = normalized(std::abs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0}));
        const Vec3 v = cross(n, u);
        std::vector<std::pair<double, Vec3>> ordered;
        ordered.reserve(f.corners.size());
        for (const Vec3& p : f.corners)
            ordered.emplace_back(detail::pseudoAngle(dot(p - center, u), dot(p - center, v)), p);
        std::sort(ordered.begin(), ordered.end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
        for (std::size_t i = 0; i < ordered.size(); ++i)
            f.corners[i] = ordered[i].second;
        faces.push_back(std::move(f));
    }
    ConvexPolytope hull = ConvexPolytope::fromFaces(std::move(faces));
    if (hull.empty() || !(hull.volume() > 0))
        return makeError(ErrorCode::InvalidInput, "convex hull: points are coplanar or degenerate");
    return hull;
}

double detail::hullVolume(const std::vector<Vec3>& points) {
    if (points.size() < 4)
        return 0;
    for (const Vec3& p : points)
        if (!isFinite(p))
            return 0;
    QhullRun run(points);
    if (!run.ok())
        return 0;
    qh_getarea(run.qh(), run.qh()->facet_list);
    return run.qh()->totvol > 0 ? run.qh()->totvol : 0;
}

namespace {

/// The planes of the hull of the points' extremes in maxFaces / 4 directions, each pushed out to the farthest
/// point: about maxFaces / 2 faces, in a few passes over the points.
Result<ConvexPolytope> pushedOutHull(const std::vector<Vec3>& points, std::size_t maxFaces) {
    const std::size_t directions = std::max<std::size_t>(8, maxFaces / 4);
    Aabb box;
    for (const Vec3& p : points)
        box.extend(p);
    // Fibonacci directions on the sphere, stretched by the box's extents so that a long part gets as many
    // extremes along its length as across it.
    const Vec3 half = box.size() * 0.5 + Vec3{1, 1, 1} * (1e-12 * (box.diagonal() + 1));
    std::vector<Vec3> extremes;
    for (std::size_t k = 0; k < directions; ++k) {
        const Vec3 u = detail::sphereDirection(k, directions);
        const Vec3 n{u.x / half.x, u.y / half.y, u.z / half.z};
        std::size_t best = 0;
        double bestDot = -std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < points.size(); ++i) {
            const double d = dot(n, points[i]);
            if (d > bestDot) {
                bestDot = d;
                best = i;
            }
        }
        extremes.push_back(points[best]);
    }
    std::sort(extremes.begin(), extremes.end(),
              [](const Vec3& a, const Vec3& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
    extremes.erase(std::unique(extremes.begin(), extremes.end()), extremes.end());
    auto inner = convexHull(extremes);
    if (!inner)
        return convexHull(points);
    // Each face plane of the inner hull pushed out to the farthest point: the polytope contains them all.
    ConvexPolytope out = ConvexPolytope::fromAabb(box);
    for (const PolytopeFaceView& f : inner->faces()) {
        double offset = -std::numeric_limits<double>::infinity();
        for (const Vec3& p : points)
            offset = std::max(offset, dot(f.plane.normal, p));
        out = out.clipped(Plane{f.plane.normal, offset});
        if (out.empty())
            return convexHull(points);
    }
    return out;
}

} // namespace

/// Above this many points per allowed face, boundedHull pushes planes out instead of choosing hull facets.
constexpr std::size_t kExactPointsPerFace = 16;

Result<ConvexPolytope> boundedHull(const std::vector<Vec3>& points, std::size_t maxFaces) {
    if (points.size() > kExactPointsPerFace * maxFaces)
        return pushedOutHull(points, maxFaces);
    auto exact = convexHull(points);
    if (!exact || exact->faces().size() <= maxFaces)
        return exact;
    // Supporting planes of the exact hull only (so the result contains every point), added where the polytope
    // reaches farthest out of the hull, a batch per round, from the points' box: until it reaches at most
    // half of kPartHullTolerance out, or (past maxFaces / 2 faces) at most maxFaces faces.
    const PolytopeFaces facets = exact->faces();
    Aabb box;
    for (const Vec3& p : points)
        box.extend(p);
    const double stop = 0.5 * partHullTolerance(box.diagonal());
    ConvexPolytope out = ConvexPolytope::fromAabb(box);
    struct Reach {
        double distance = 0;
        std::size_t facet = 0;
    };
    std::map<std::tuple<double, double, double>, Reach> reach; // per corner, the facet it is farthest out of
    for (std::size_t round = 0; round < maxFaces; ++round) {
        std::vector<std::pair<double, std::size_t>> violated; // (distance, facet), one per facet
        std::vector<bool> taken(facets.size(), false);
        for (const PolytopeFaceView& f : out.faces())
            for (const Vec3& c : f.corners) {
                auto [it, fresh] = reach.try_emplace(std::make_tuple(c.x, c.y, c.z));
                if (fresh) {
                    it->second.distance = -std::numeric_limits<double>::infinity();
                    for (std::size_t k = 0; k < facets.size(); ++k)
                        if (const double d = facets[k].plane.signedDistance(c); d > it->second.distance)
                            it->second = {d, k};
                }
                if (it->second.distance > stop && !taken[it->second.facet]) {
                    taken[it->second.facet] = true;
                    violated.emplace_back(it->second.distance, it->second.facet);
                }
            }
        if (violated.empty())
            break;
        const std::size_t faces = out.faces().size();
        const std::size_t room = faces < maxFaces / 2 ? maxFaces / 2 - faces : (faces < maxFaces ? 1 : 0);
        if (room == 0)
            break;
        std::sort(violated.begin(), violated.end(), std::greater<>());
        if (violated.size() > room)
            violated.resize(room);
        for (const auto& [d, k] : violated) {
            ConvexPolytope next = out.clipped(facets[k].plane);
            if (next.empty())
                return exact;
            out = std::move(next);
        }
    }
    return out;
}

} // namespace rubble
