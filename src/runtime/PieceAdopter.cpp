#include "runtime/PieceAdopter.hpp"

#include <algorithm>
#include <cmath>

#include "rubble/collision/ConvexDecomposition.hpp"

namespace rubble::detail {

PieceSpawn describeObjectBody(const ObjectState& st, bool isStatic, double singleHullVolume) {
    PieceSpawn s;
    s.object = st.id;
    s.objectToBody = Frame{st.mass.principalAxes, st.mass.centerOfMass};
    s.volume = std::abs(st.mass.volume);
    s.triangles = st.mesh.triangleCount();
    s.isStatic = isStatic;
    const double floorMoment = 1e-9 * std::max(s.volume, 1e-12);
    s.mass = st.density * s.volume;
    s.inertia = Vec3{std::max(st.mass.principalMoments.x, floorMoment),
                     std::max(st.mass.principalMoments.y, floorMoment),
                     std::max(st.mass.principalMoments.z, floorMoment)} *
                st.density;
    const Frame toBody = s.objectToBody.inverse();
    BodyShape& shape = s.desc.shape;
    shape.kind = BodyShape::Kind::Convex;
    if (st.convexParts.size() > 1 && s.volume < singleHullVolume) { // small: one hull is cheaper
        std::vector<Vec3> points;
        for (const ConvexPolytope& part : st.convexParts)
            for (const Vec3& p : part.vertices())
                points.push_back(toBody.apply(p));
        if (Result<ConvexPolytope> hull = convexHull(points))
            shape.parts.push_back(std::move(hull).value());
    }
    if (shape.parts.empty())
        for (const ConvexPolytope& part : st.convexParts)
            shape.parts.push_back(part.transformed(toBody));
    if (shape.parts.empty()) // no convex parts: the hull of the mesh
        for (const Vec3& p : st.mesh.positions)
            shape.points.push_back(toBody.apply(p));
    s.desc.mass = isStatic ? 0.0 : s.mass;
    s.desc.inertia = isStatic ? Vec3{} : s.inertia;
    return s;
}

AdoptionPlan planAdoption(const FractureOutcome& outcome, const BodyRecord& parent,
                          const BodyMotion& parentMotion, const AdoptionPolicy& policy, bool collapse,
                          double particleLifetime, bool bondDebris) {
    AdoptionPlan plan;
    const Frame parentObject = parentMotion.transform * parent.objectToBody.inverse();
    const Vec3 v = parentMotion.linearVelocity, w = parentMotion.angularVelocity;
    const Vec3 c = parentMotion.transform.translation;
    const bool structural = parent.motion == BodyMotionState::Static;
    const bool engineStatic = parent.motion != BodyMotionState::Dynamic; // static or frozen: took no impulse
    const bool keepRemainder = structural && policy.keepStaticRemainder;
    collapse = collapse && keepRemainder;
    const bool floating = collapse && parent.anchor;
    const auto& pieces = outcome.pieces;
    auto isRemainder = [&](std::size_t i) { return pieces[i].cell < 0; };
    // The piece that stays static whatever its support: the largest (of the remainder, for a floating
    // parent).
    std::size_t keep = pieces.size();
    if (keepRemainder && (!collapse || floating)) {
        double best = -1;
        for (std::size_t i = 0; i < pieces.size(); ++i)
            if (pieces[i].state->mass.volume > best && (!floating || isRemainder(i))) {
                best = pieces[i].state->mass.volume;
                keep = i;
            }
    }
    // Debris of a static (or frozen) body is thrown outward by the hit: a share of the impulse, split by mass
    // (so all debris of one hit gets the same speed), along the surface normal and away from the impact.
    double debrisMass = 0;
    if (engineStatic && policy.debrisKick > 0 && !outcome.impacts.empty()) {
        for (const AdoptedPiece& p : pieces)
            if (p.cell >= 0)
                debrisMass += p.state->density * std::abs(p.state->mass.volume);
        for (const DustPiece& d : outcome.dust)
            if (d.cell >= 0)
                debrisMass +=
                    parent.mass > 0 && parent.volume > 0 ? d.volume * parent.mass / parent.volume : d.volume;
    }
    auto kick = [&](std::int32_t cell, const Vec3& at) { // at: parent local coordinates
        if (debrisMass <= 0 || cell < 0)
            return Vec3{};
        const Impact* hit = &outcome.impacts.front();
        for (const Impact& m : outcome.impacts)
            if (lengthSquared(m.point - at) < lengthSquared(hit->point - at))
                hit = &m;
        Vec3 dir = normalized(hit->normal);
        if (const Vec3 away = at - hit->point; lengthSquared(away) > 0)
            dir = normalized(dir + 0.5 * normalized(away));
        const double speed =
            std::min(policy.debrisKick * hit->impulse / debrisMass, policy.maxDebrisKickSpeed);
        return parentObject.rotation * (dir * speed);
    };
    for (std::size_t i = 0; i < pieces.size(); ++i) {
        const AdoptedPiece& p = pieces[i];
        const bool checked = collapse && !floating && (isRemainder(i) || bondDebris);
        const bool isStatic = i == keep || checked;
        PieceSpawn s = describeObjectBody(*p.state, isStatic, policy.singleHullVolume);
        s.desc.transform = parentObject * p.frame * s.objectToBody;
        s.desc.friction = policy.friction;
        s.desc.restitution = policy.restitution;
        if (!isStatic) {
            s.desc.linearVelocity =
                v + cross(w, s.desc.transform.translation - c) + kick(p.cell, p.frame.translation);
            s.desc.angularVelocity = w;
        }
        s.structural = isStatic && collapse;
        s.anchor = floating && i == keep;
        plan.spawns.push_back(std::move(s));
    }
    for (const DustPiece& d : outcome.dust) {
        const Vec3 at = parentObject.apply(d.center);
        plan.particles.push_back({at, v + cross(w, at - c) + kick(d.cell, d.center), std::cbrt(d.volume),
                                  d.volume, particleLifetime});
    }
    return plan;
}

} // namespace rubble::detail
