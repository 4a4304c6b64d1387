#include "rubble/bullet/CollisionShape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <BulletCollision/BroadphaseCollision/btDbvt.h>
#include <BulletCollision/CollisionShapes/btShapeHull.h>

#include "rubble/bullet/Convert.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"

namespace rubble::bullet {
namespace {

// body coordinates of an object-coordinate point
Vec3 toBody(const Frame& objectToBody, const Vec3& p) {
    return objectToBody.rotation.transposed() * (p - objectToBody.translation);
}

bool lexLess(const Vec3& a, const Vec3& b) {
    if (a.x != b.x)
        return a.x < b.x;
    if (a.y != b.y)
        return a.y < b.y;
    return a.z < b.z;
}

// The points sorted, each once; empty when under four (no core).
std::vector<Vec3> distinctCorners(std::vector<Vec3> points) {
    std::sort(points.begin(), points.end(), lexLess);
    points.erase(std::unique(points.begin(), points.end()), points.end());
    if (points.size() < 4)
        return {};
    return points;
}

// The part shrunk by margin along every face plane (empty when it is thinner than 2·margin).
ConvexPolytope eroded(const ConvexPolytope& part, double margin) {
    ConvexPolytope out = part;
    for (const PolytopeFaceView& f : part.faces()) {
        out = out.clipped(Plane{f.plane.normal, f.plane.offset - margin}, f.tag);
        if (out.empty())
            break;
    }
    return out;
}

// The part's core corners from its corners' moved-in planes (docs/collision.md); empty when under four.
std::vector<Vec3> shiftedCorners(const ConvexPolytope& part, double margin) {
    constexpr std::size_t kMostFacesAtCorner = 24;
    const std::vector<Vec3>& corners = part.corners();
    std::vector<std::uint32_t> start(corners.size() + 1, 0); // faces at corner k: at[start[k], start[k + 1])
    std::vector<Plane> planes;
    planes.reserve(part.faces().size());
    for (const PolytopeFaceView& f : part.faces()) {
        planes.push_back({f.plane.normal, f.plane.offset - margin});
        for (const Vec3& c : f.corners)
            ++start[static_cast<std::size_t>(&c - corners.data()) + 1];
    }
    for (std::size_t k = 0; k < corners.size(); ++k)
        start[k + 1] += start[k];
    std::vector<std::uint32_t> at(start.back()), next(start.begin(), start.end() - 1);
    std::uint32_t face = 0;
    for (const PolytopeFaceView& f : part.faces()) {
        for (const Vec3& c : f.corners)
            at[next[static_cast<std::size_t>(&c - corners.data())]++] = face;
        ++face;
    }
    const Aabb b = part.bounds();
    const double tol = 1e-9 * std::max(1.0, std::max({std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.lo.z),
                                                      std::abs(b.hi.x), std::abs(b.hi.y), std::abs(b.hi.z)}));
    std::vector<Vec3> out;
    for (std::size_t k = 0; k < corners.size(); ++k) {
        const std::uint32_t* f = at.data() + start[k];
        const std::size_t n = start[k + 1] - start[k];
        if (n > kMostFacesAtCorner)
            return {};
        auto insideAll = [&](const Vec3& x, const std::uint32_t* ids, std::size_t count) {
            for (std::size_t i = 0; i < count; ++i)
                if (!(planes[ids[i]].signedDistance(x) <= tol))
                    return false;
            return true;
        };
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = i + 1; j < n; ++j)
                for (std::size_t l = j + 1; l < n; ++l) {
                    const Plane& p = planes[f[i]];
                    const Plane& q = planes[f[j]];
                    const Plane& r = planes[f[l]];
                    const Vec3 qr = cross(q.normal, r.normal), rp = cross(r.normal, p.normal),
                               pq = cross(p.normal, q.normal);
                    const double det = dot(p.normal, qr);
                    if (!(std::abs(det) > 1e-9))
                        continue;
                    const Vec3 x = (qr * p.offset + rp * q.offset + pq * r.offset) / det;
                    if (insideAll(x, f, n)) // near this corner first, then everywhere
                        if (std::all_of(planes.begin(), planes.end(),
                                        [&](const Plane& plane) { return plane.signedDistance(x) <= tol; }))
                            out.push_back(x);
                }
    }
    return distinctCorners(std::move(out));
}

// The part's core corners from the polar of its moved-in planes about its centroid (docs/collision.md).
std::vector<Vec3> polarCorners(const ConvexPolytope& part, double margin) {
    const Vec3 c = part.centroid();
    const double scale = std::max(1.0, part.bounds().diagonal());
    std::vector<Vec3> dual;
    dual.reserve(part.faces().size());
    for (const PolytopeFaceView& f : part.faces()) {
        const double gap = f.plane.offset - margin - dot(f.plane.normal, c);
        if (!(gap > 1e-6 * scale))
            return {};
        dual.push_back(f.plane.normal / gap);
    }
    Result<ConvexPolytope> hull = convexHull(dual);
    if (!hull)
        return {};
    std::vector<Vec3> out;
    out.reserve(hull->faces().size());
    for (const PolytopeFaceView& f : hull->faces()) {
        if (!(f.plane.offset > 0))
            return {};
        out.push_back(c + f.plane.normal / f.plane.offset);
    }
    return distinctCorners(std::move(out));
}

// Directions spread evenly over the sphere (a Fibonacci lattice): where a capped hull's support is compared.
const std::vector<Vec3>& sphereDirections() {
    static const std::vector<Vec3> directions = [] {
        constexpr int n = 128;
        const double turn = 3.14159265358979323846 * (3 - std::sqrt(5.0));
        std::vector<Vec3> out;
        out.reserve(n);
        for (int i = 0; i < n; ++i) {
            const double y = 1 - (2.0 * i + 1) / n;
            const double r = std::sqrt(1 - y * y);
            out.push_back({r * std::cos(turn * i), y, r * std::sin(turn * i)});
        }
        return out;
    }();
    return directions;
}

} // namespace

std::vector<Vec3> CollisionShape::cappedHullPoints(const std::vector<Vec3>& points, int maxPoints) {
    if (maxPoints < 4 || points.size() <= static_cast<std::size_t>(maxPoints))
        return points;
    const std::vector<Vec3>& dirs = sphereDirections();
    std::vector<double> full(dirs.size(), -std::numeric_limits<double>::infinity());
    std::vector<double> kept(dirs.size(), -std::numeric_limits<double>::infinity());
    std::vector<std::size_t> extreme(dirs.size(), 0);
    for (std::size_t d = 0; d < dirs.size(); ++d)
        for (std::size_t i = 0; i < points.size(); ++i)
            if (const double h = dot(dirs[d], points[i]); h > full[d]) {
                full[d] = h;
                extreme[d] = i;
            }
    // Greedy: the point that holds up the support where the kept points fall shortest.
    std::vector<Vec3> out;
    std::vector<char> taken(points.size(), 0);
    while (out.size() < static_cast<std::size_t>(maxPoints)) {
        std::size_t worst = 0;
        double gap = 0;
        for (std::size_t d = 0; d < dirs.size(); ++d)
            if (full[d] - kept[d] > gap) {
                gap = full[d] - kept[d];
                worst = d;
            }
        if (gap <= 0 || taken[extreme[worst]])
            break;
        const Vec3& p = points[extreme[worst]];
        taken[extreme[worst]] = 1;
        out.push_back(p);
        for (std::size_t d = 0; d < dirs.size(); ++d)
            kept[d] = std::max(kept[d], dot(dirs[d], p));
    }
    return out.size() < 4 ? points : out;
}

std::vector<Vec3> CollisionShape::coreCorners(const ConvexPolytope& part, double margin) {
    if (!(margin > 0))
        return part.vertices();
    if (std::vector<Vec3> fast = shiftedCorners(part, margin); !fast.empty())
        return fast;
    if (std::vector<Vec3> polar = polarCorners(part, margin); !polar.empty())
        return polar;
    return eroded(part, margin).vertices();
}

CollisionShape::~CollisionShape() = default;

int CollisionShape::childCount() const {
    if (compound_)
        return compound_->getNumChildShapes();
    return root_ && root_->getShapeType() == CONVEX_HULL_SHAPE_PROXYTYPE ? 1 : 0;
}

CollisionShape::Bytes CollisionShape::bytes() const {
    Bytes b;
    b.shapes = sizeof(CollisionShape) + children_.capacity() * sizeof(children_[0]);
    if (compound_) {
        b.shapes += sizeof(btCompoundShape) +
                    static_cast<std::size_t>(compound_->getNumChildShapes()) * sizeof(btCompoundShapeChild);
        if (const btDbvt* tree = compound_->getDynamicAabbTree())
            b.shapes += sizeof(btDbvt) + (2 * static_cast<std::size_t>(tree->m_leaves)) * sizeof(btDbvtNode);
    }
    for (const auto& child : children_)
        if (child->getShapeType() == CONVEX_HULL_SHAPE_PROXYTYPE) {
            const int n = static_cast<const btConvexHullShape&>(*child).getNumPoints();
            b.shapes += sizeof(btConvexHullShape) + static_cast<std::size_t>(n) * sizeof(btVector3);
            b.points += static_cast<std::size_t>(n);
        } else {
            b.shapes += sizeof(btBoxShape);
        }
    b.edges = edgePoints_.capacity() * sizeof(Vec3f) + edgeIndex_.capacity() * sizeof(edgeIndex_[0]);
    return b;
}

std::vector<std::array<Vec3, 2>> CollisionShape::edges() const {
    std::vector<std::array<Vec3, 2>> out;
    out.reserve(edgeIndex_.size());
    for (const auto& e : edgeIndex_)
        out.push_back({edgePoints_[e[0]], edgePoints_[e[1]]});
    return out;
}

void CollisionShape::addEdge(const Vec3& a, const Vec3& b) {
    const auto i = static_cast<std::uint32_t>(edgePoints_.size());
    edgePoints_.emplace_back(a);
    edgePoints_.emplace_back(b);
    edgeIndex_.push_back({i, i + 1});
}

std::unique_ptr<CollisionShape> CollisionShape::fromParts(const std::vector<ConvexPolytope>& parts,
                                                          const std::vector<Vec3>& fallbackPoints,
                                                          const Frame& objectToBody, double margin,
                                                          int maxHullPoints) {
    std::unique_ptr<CollisionShape> s(new CollisionShape());
    s->compound_ = std::make_unique<btCompoundShape>(true, static_cast<int>(parts.size()));
    btTransform identity;
    identity.setIdentity();
    for (const ConvexPolytope& part : parts) {
        if (part.empty())
            continue;
        const Aabb b = part.bounds();
        const Vec3 size = b.size();
        double m = std::min(margin, 0.2 * std::min({size.x, size.y, size.z}));
        std::vector<Vec3> core = coreCorners(part, m);
        for (int attempt = 0; attempt < 4 && core.empty() && m > 0; ++attempt) {
            m *= 0.25;
            core = coreCorners(part, m);
        }
        if (core.empty()) {
            core = part.vertices();
            m = 0;
        }
        const std::vector<Vec3> verts = cappedHullPoints(core, maxHullPoints);
        if (verts.size() < 4)
            continue;
        std::vector<btVector3> points; // copied once into a hull of exactly this size
        points.reserve(verts.size());
        for (const Vec3& v : verts)
            points.push_back(toBt(toBody(objectToBody, v)));
        auto hull = std::make_unique<btConvexHullShape>(&points[0].x(), static_cast<int>(points.size()),
                                                        static_cast<int>(sizeof(btVector3)));
        hull->setMargin(static_cast<btScalar>(std::max(m, 1e-4)));
        hull->recalcLocalAabb();
        s->compound_->addChildShape(identity, hull.get());
        s->children_.push_back(std::move(hull));
        // each corner once, each edge as two indices
        std::vector<Vec3> corners = part.vertices();
        std::sort(corners.begin(), corners.end(), lexLess);
        const auto base = static_cast<std::uint32_t>(s->edgePoints_.size());
        for (const Vec3& c : corners)
            s->edgePoints_.emplace_back(toBody(objectToBody, c));
        auto index = [&](const Vec3& p) {
            return base + static_cast<std::uint32_t>(
                              std::lower_bound(corners.begin(), corners.end(), p, lexLess) - corners.begin());
        };
        for (const PolytopeFaceView& f : part.faces())
            for (std::size_t i = 0; i < f.corners.size(); ++i) {
                const Vec3& a = f.corners[i];
                const Vec3& c = f.corners[(i + 1) % f.corners.size()];
                if (lexLess(a, c))
                    s->edgeIndex_.push_back({index(a), index(c)});
            }
    }
    if (s->children_.empty()) {
        if (fallbackPoints.size() < 4)
            return nullptr;
        btConvexHullShape raw;
        for (const Vec3& p : fallbackPoints)
            raw.addPoint(toBt(toBody(objectToBody, p)), false);
        raw.recalcLocalAabb();
        btShapeHull reducer(&raw);
        reducer.buildHull(raw.getMargin());
        auto hull = std::make_unique<btConvexHullShape>();
        const int n = reducer.numVertices();
        for (int i = 0; i < n; ++i)
            hull->addPoint(reducer.getVertexPointer()[i], false);
        if (n < 4)
            for (int i = 0; i < raw.getNumPoints(); ++i)
                hull->addPoint(raw.getUnscaledPoints()[i], false);
        hull->setMargin(static_cast<btScalar>(std::min(margin, 0.01)));
        hull->recalcLocalAabb();
        const unsigned int* idx = reducer.getIndexPointer();
        for (int t = 0; t + 2 < reducer.numIndices(); t += 3)
            for (int e = 0; e < 3; ++e) {
                const btVector3& a = reducer.getVertexPointer()[idx[t + e]];
                const btVector3& c = reducer.getVertexPointer()[idx[t + (e + 1) % 3]];
                s->addEdge(fromBt(a), fromBt(c));
            }
        s->compound_->addChildShape(identity, hull.get());
        s->children_.push_back(std::move(hull));
    }
    s->edgePoints_.shrink_to_fit();
    s->edgeIndex_.shrink_to_fit();
    s->root_ = s->compound_.get();
    if (s->children_.size() == 1) { // one hull collides without the compound's per-pair bookkeeping
        s->compound_.reset();
        s->root_ = s->children_.front().get();
    }
    return s;
}

std::unique_ptr<CollisionShape> CollisionShape::box(const Vec3& halfExtents) {
    std::unique_ptr<CollisionShape> s(new CollisionShape());
    auto box = std::make_unique<btBoxShape>(toBt(halfExtents));
    s->root_ = box.get();
    s->children_.push_back(std::move(box));
    const Vec3 h = halfExtents;
    for (int axis = 0; axis < 3; ++axis)
        for (int i = 0; i < 4; ++i) {
            Vec3 lo, hi;
            const double u = (i & 1) ? 1 : -1, v = (i & 2) ? 1 : -1;
            if (axis == 0) {
                lo = {-h.x, u * h.y, v * h.z};
                hi = {h.x, u * h.y, v * h.z};
            } else if (axis == 1) {
                lo = {u * h.x, -h.y, v * h.z};
                hi = {u * h.x, h.y, v * h.z};
            } else {
                lo = {u * h.x, v * h.y, -h.z};
                hi = {u * h.x, v * h.y, h.z};
            }
            s->addEdge(lo, hi);
        }
    return s;
}

std::unique_ptr<CollisionShape> CollisionShape::sphere(double radius) {
    std::unique_ptr<CollisionShape> s(new CollisionShape());
    auto sph = std::make_unique<btSphereShape>(static_cast<btScalar>(radius));
    s->root_ = sph.get();
    s->children_.push_back(std::move(sph));
    const int n = 12;
    for (int axis = 0; axis < 3; ++axis)
        for (int i = 0; i < n; ++i) {
            const double a0 = 2 * 3.14159265358979 * i / n, a1 = 2 * 3.14159265358979 * (i + 1) / n;
            auto pt = [&](double a) {
                Vec3 p;
                p[(axis + 1) % 3] = radius * std::cos(a);
                p[(axis + 2) % 3] = radius * std::sin(a);
                return p;
            };
            s->addEdge(pt(a0), pt(a1));
        }
    return s;
}

} // namespace rubble::bullet
