// Approximate convex decomposition by recursive plane cuts (the idea of CoACD, simplified for speed).
//
// Every part is a convex region R (an enlarged bounding box cut by planes) and its convex shape is the exact
// hull of (solid ∩ R): the hull of the mesh triangles clipped to R plus R's corners inside the solid. Regions
// partition space, so parts never overlap and together cover the solid. The part whose hull is deepest
// away from the mesh (rays cast inward from its hull faces) is split next, by the candidate plane (axis and
// principal-axis planes through the deepest pocket) that gives the smallest total hull volume, until
// params.maxParts or every part is within params.concavity · diagonal of the mesh.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "collision/MeshRegion.hpp"
#include "rubble/ConvexDecomposition.hpp"
#include "rubble/MassProperties.hpp"

namespace rubble {

namespace {

using detail::Polygon;

struct Part {
    ConvexPolytope region;
    std::vector<Polygon> surface; // mesh triangles clipped to region
    ConvexPolytope hull;
    double depth = 0; // deepest pocket between hull and mesh
    Vec3 pocket;      // where that pocket's bottom is
    Vec3 pocketDir;   // inward hull normal there
};

class Decomposer {
public:
    Decomposer(const Mesh& mesh, const DecompositionParams& params) : mesh_(mesh), params_(params) {
        diag_ = mesh.bounds().diagonal();
    }

    bool inside(const Vec3& p) {
        auto key = std::make_tuple(p.x, p.y, p.z);
        auto it = insideCache_.find(key);
        if (it != insideCache_.end())
            return it->second;
        const bool in = detail::insideMesh(mesh_, p);
        insideCache_.emplace(key, in);
        return in;
    }

    std::optional<ConvexPolytope> hullOf(const std::vector<Polygon>& surface, const ConvexPolytope& region) {
        std::vector<Vec3> extra;
        for (const Vec3& v : region.vertices())
            if (inside(v))
                extra.push_back(v);
        if (surface.empty() && extra.size() < 4)
            return std::nullopt;
        auto h = detail::hullOfPolygons(surface, extra);
        if (!h)
            return std::nullopt;
        return std::move(h.value());
    }

    /// Deepest pocket between the hull and the surface, from rays cast inward at samples of hull faces that
    /// do not lie on a cut plane of the region.
    void measureDepth(Part& part) const {
        part.depth = 0;
        const double delta = 1e-9 * std::max(diag_, 1.0);
        const double planeTol = 1e-7 * std::max(diag_, 1.0);
        std::vector<const PolytopeFace*> cuts;
        for (const PolytopeFace& f : part.region.faces())
            if (f.tag >= 0)
                cuts.push_back(&f);
        std::vector<Vec3> samples;
        for (const PolytopeFace& hf : part.hull.faces()) {
            bool onCut = false;
            for (const PolytopeFace* c : cuts)
                if (dot(c->plane.normal, hf.plane.normal) > 1 - 1e-9 &&
                    std::abs(c->plane.offset - hf.plane.offset) < planeTol)
                    onCut = true;
            if (onCut)
                continue;
            Vec3 g;
            for (const Vec3& c : hf.corners)
                g += c;
            g = g / static_cast<double>(hf.corners.size());
            samples.clear();
            samples.push_back(g);
            const std::size_t n = hf.corners.size();
            for (std::size_t i = 0; i < n; ++i) {
                const Vec3& a = hf.corners[i];
                const Vec3& b = hf.corners[(i + 1) % n];
                samples.push_back(g + (a - g) * 0.6);
                samples.push_back(g + ((a + b) * 0.5 - g) * 0.6);
            }
            const Vec3 dir = -hf.plane.normal;
            for (const Vec3& s : samples) {
                const Vec3 o = s + hf.plane.normal * delta;
                double tExit = std::numeric_limits<double>::infinity();
                for (const PolytopeFace& f : part.hull.faces()) {
                    const double nd = dot(f.plane.normal, dir);
                    if (nd > 1e-12)
                        tExit = std::min(tExit, (f.plane.offset - dot(f.plane.normal, o)) / nd);
                }
                double t = tExit;
                for (const Polygon& poly : part.surface) {
                    for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
                        const double h = rayTriangle(o, dir, poly[0], poly[k], poly[k + 1]);
                        if (h >= 0 && h < t)
                            t = h;
                    }
                    if (t <= delta * 2)
                        break;
                }
                const double depth = t - delta;
                if (depth > part.depth) {
                    part.depth = depth;
                    part.pocket = o + dir * t;
                    part.pocketDir = dir;
                }
            }
        }
    }

    static double rayTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
        const Vec3 e1 = b - a, e2 = c - a;
        const Vec3 p = cross(d, e2);
        const double det = dot(e1, p);
        if (std::abs(det) < 1e-300)
            return -1;
        const double inv = 1.0 / det;
        const Vec3 s = o - a;
        const double u = dot(s, p) * inv;
        if (u < 0 || u > 1)
            return -1;
        const Vec3 q = cross(s, e1);
        const double v = dot(d, q) * inv;
        if (v < 0 || u + v > 1)
            return -1;
        return dot(e2, q) * inv;
    }

    struct Split {
        double score = std::numeric_limits<double>::infinity();
        Part left, right;
    };

    std::optional<Part> makePart(ConvexPolytope region, std::vector<Polygon> surface) {
        auto h = hullOf(surface, region);
        if (!h)
            return std::nullopt;
        Part p;
        p.region = std::move(region);
        p.surface = std::move(surface);
        p.hull = std::move(*h);
        return p;
    }

    std::optional<Split> trySplit(const Part& part, const Plane& plane) {
        ConvexPolytope rin = part.region.clipped(plane, nextTag_);
        ConvexPolytope rout = part.region.clippedOutside(plane, nextTag_);
        if (rin.empty() || rout.empty())
            return std::nullopt;
        std::vector<Polygon> sin, sout;
        Polygon a, b;
        for (const Polygon& poly : part.surface) {
            detail::splitPolygon(poly, plane, a, b);
            if (a.size() >= 3)
                sin.push_back(a);
            if (b.size() >= 3)
                sout.push_back(b);
        }
        auto l = makePart(std::move(rin), std::move(sin));
        auto r = makePart(std::move(rout), std::move(sout));
        if (!l || !r)
            return std::nullopt;
        const double minVol = std::max(1e-9 * part.hull.volume(), minPartVolume_);
        if (l->hull.volume() < minVol || r->hull.volume() < minVol)
            return std::nullopt;
        Split s;
        s.score = l->hull.volume() + r->hull.volume();
        s.left = std::move(*l);
        s.right = std::move(*r);
        return s;
    }

    std::vector<Vec3> candidateNormals(const Part& part) const {
        std::vector<Vec3> normals = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        // Principal axes of the hull's vertices.
        const std::vector<Vec3> v = part.hull.vertices();
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
            const Vec3 n = normalized(normals[i] - part.pocketDir * dot(normals[i], part.pocketDir));
            bool dup = lengthSquared(n) < 0.5;
            for (const Vec3& m : normals)
                dup |= std::abs(dot(n, m)) > 0.999;
            if (!dup)
                normals.push_back(n);
        }
        return normals;
    }

    Result<Decomposition> run() {
        Decomposition out;
        out.meshVolume = signedVolume(mesh_);
        if (mesh_.empty() || !(out.meshVolume > 0))
            return makeError(ErrorCode::InvalidInput,
                             "decompose: the mesh must be closed with positive volume (volume " +
                                 std::to_string(out.meshVolume) + ")");
        Aabb box = mesh_.bounds();
        const Vec3 pad = Vec3{1, 1, 1} * (0.01 * diag_ + 1e-9);
        box.lo -= pad;
        box.hi += pad;
        auto hull = convexHull(mesh_.positions);
        if (!hull)
            return hull.error();
        double area = 0;
        for (const PolytopeFace& f : hull->faces())
            for (std::size_t i = 1; i + 1 < f.corners.size(); ++i)
                area += 0.5 * length(cross(f.corners[i] - f.corners[0], f.corners[i + 1] - f.corners[0]));
        const double threshold = params_.concavity * diag_;
        minPartVolume_ = params_.minPartVolumeFraction * out.meshVolume;
        if (params_.maxParts <= 1 || hull->volume() - out.meshVolume <= 0.01 * threshold * area) {
            out.hullVolume = hull->volume();
            out.parts.push_back(std::move(hull.value()));
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
            root.hull = std::move(hull.value());
            measureDepth(root);
            parts.push_back(std::move(root));
        }
        std::vector<bool> done(1, false);
        while (static_cast<int>(parts.size()) < params_.maxParts) {
            int best = -1;
            for (std::size_t i = 0; i < parts.size(); ++i)
                if (!done[i] && parts[i].depth > threshold &&
                    (best < 0 || parts[i].depth > parts[best].depth))
                    best = static_cast<int>(i);
            if (best < 0)
                break;
            const Part& part = parts[best];
            std::optional<Split> chosen;
            for (const Vec3& n : candidateNormals(part)) {
                for (const Vec3& through : {part.pocket}) {
                    auto s = trySplit(part, Plane::fromPointNormal(through, n));
                    if (s && (!chosen || s->score < chosen->score))
                        chosen = std::move(s);
                }
            }
            if (!chosen || chosen->score > part.hull.volume() * (1 + 1e-9)) {
                done[best] = true;
                continue;
            }
            ++nextTag_;
            measureDepth(chosen->left);
            measureDepth(chosen->right);
            parts[best] = std::move(chosen->left);
            done[best] = false;
            parts.push_back(std::move(chosen->right));
            done.push_back(false);
        }
        const double minVol = params_.minPartVolumeFraction * out.meshVolume;
        for (Part& p : parts) {
            const double v = p.hull.volume();
            if (v < minVol && parts.size() > 1)
                continue;
            out.hullVolume += v;
            out.parts.push_back(std::move(p.hull));
        }
        return out;
    }

private:
    const Mesh& mesh_;
    DecompositionParams params_;
    double diag_ = 0;
    std::int32_t nextTag_ = 0;
    double minPartVolume_ = 0;
    std::map<std::tuple<double, double, double>, bool> insideCache_;
};

} // namespace

Result<Decomposition> decompose(const Mesh& mesh, const DecompositionParams& params) {
    if (const Status s = mesh.validate(); !s)
        return s.error();
    if (mesh.triangles.size() < 4)
        return makeError(ErrorCode::InvalidInput, "decompose: a closed mesh needs at least 4 triangles");
    Decomposer d(mesh, params);
    return d.run();
}

} // namespace rubble
