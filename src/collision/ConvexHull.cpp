// Convex hull of a point set through Qhull's reentrant C API (libqhull_r). Qhull reports errors with
// setjmp/longjmp inside qh_new_qhull and returns an exit code; its messages go to an in-memory stream that
// becomes the error message, so nothing is printed and nothing exits.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include "rubble/ConvexDecomposition.hpp"

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
} // namespace

Result<ConvexPolytope> convexHull(const std::vector<Vec3>& points) {
    if (points.size() < 4)
        return makeError(ErrorCode::InvalidInput,
                         "convex hull needs at least 4 points, got " + std::to_string(points.size()));
    std::vector<coordT> coords;
    coords.reserve(points.size() * 3);
    for (const Vec3& p : points) {
        if (!isFinite(p))
            return makeError(ErrorCode::InvalidInput, "convex hull: non-finite point");
        coords.insert(coords.end(), {p.x, p.y, p.z});
    }
    MessageStream errors;
    FILE* err = errors.file() ? errors.file() : stderr;
    qhT qhStorage;
    qhT* qh = &qhStorage;
    qh_zero(qh, err);
    char command[] = "qhull Pp";
    const int exitCode =
        qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False, command, nullptr, err);
    Result<ConvexPolytope> result = makeError(ErrorCode::GeometryFailure, "convex hull failed");
    if (exitCode != 0) {
        std::string msg = errors.text();
        const bool flat = msg.find("QH6154") != std::string::npos || msg.find("flat") != std::string::npos ||
                          msg.find("QH6214") != std::string::npos || msg.find("QH6271") != std::string::npos;
        result = makeError(flat ? ErrorCode::InvalidInput : ErrorCode::GeometryFailure,
                           std::string("convex hull: ") +
                               (flat ? "points are coplanar or degenerate" : "Qhull failed") +
                               (msg.empty() ? "" : " (" + msg + ")"));
    } else {
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
            const Vec3 u =
                normalized(std::abs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0}));
            const Vec3 v = cross(n, u);
            std::vector<std::pair<double, Vec3>> ordered;
            ordered.reserve(f.corners.size());
            for (const Vec3& p : f.corners)
                ordered.emplace_back(std::atan2(dot(p - center, v), dot(p - center, u)), p);
            std::sort(ordered.begin(), ordered.end(),
                      [](const auto& a, const auto& b) { return a.first < b.first; });
            for (std::size_t i = 0; i < ordered.size(); ++i)
                f.corners[i] = ordered[i].second;
            faces.push_back(std::move(f));
        }
        ConvexPolytope hull = ConvexPolytope::fromFaces(std::move(faces));
        if (hull.empty() || !(hull.volume() > 0))
            result = makeError(ErrorCode::InvalidInput, "convex hull: points are coplanar or degenerate");
        else
            result = std::move(hull);
    }
    qh_freeqhull(qh, !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(qh, &curlong, &totlong);
    return result;
}

} // namespace rubble
