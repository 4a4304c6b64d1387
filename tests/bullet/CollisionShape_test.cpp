// Bullet-only parts of the adapter: shapes from convex parts, fixed stepping, bodies placed at their centre
// of mass.
#include <gtest/gtest.h>

#include <cmath>

#include "rubble/bullet/CollisionShape.hpp"
#include "rubble/bullet/Convert.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/MassProperties.hpp"

using namespace rubble;
using namespace rubble::bullet;

TEST(CollisionShape, ErodedHullPlusMarginMatchesThePart) {
    const ConvexPolytope part = ConvexPolytope::fromAabb(Aabb{{0, 0, 0}, {2, 1, 4}});
    const Frame objectToBody{Mat3::identity(), {1, 0.5, 2}};
    auto shape = CollisionShape::fromParts({part}, {}, objectToBody, 0.05);
    ASSERT_TRUE(shape);
    EXPECT_EQ(shape->childCount(), 1);
    // one part collides as its hull, without a compound; hull points + margin hug the part's box
    ASSERT_EQ(shape->shape()->getShapeType(), CONVEX_HULL_SHAPE_PROXYTYPE);
    auto* hull = static_cast<btConvexHullShape*>(shape->shape());
    const double m = hull->getMargin();
    EXPECT_NEAR(m, 0.05, 1e-6);
    btVector3 lo(1e9f, 1e9f, 1e9f), hi(-1e9f, -1e9f, -1e9f);
    for (int i = 0; i < hull->getNumPoints(); ++i) {
        lo.setMin(hull->getUnscaledPoints()[i]);
        hi.setMax(hull->getUnscaledPoints()[i]);
    }
    EXPECT_NEAR(lo.x() - m, -1.0, 1e-5);
    EXPECT_NEAR(hi.y() + m, 0.5, 1e-5);
    EXPECT_NEAR(hi.z() + m, 2.0, 1e-5);
    EXPECT_EQ(shape->edges().size(), 12u);
}

// The core a hull collides with (its corners + the margin make the part) lies in the part clipped by every
// face plane moved in by the margin, and misses little of it.
TEST(CollisionShape, CoreCornersAreThePartShrunkByTheMargin) {
    auto clippedCore = [](const ConvexPolytope& part, double margin) {
        ConvexPolytope out = part;
        for (const PolytopeFaceView& f : part.faces())
            out = out.clipped(Plane{f.plane.normal, f.plane.offset - margin});
        return out;
    };
    Rng rng(7);
    std::vector<ConvexPolytope> parts;
    parts.push_back(ConvexPolytope::fromAabb(Aabb{{0, 0, 0}, {2, 1, 4}}));
    parts.push_back(parts.back().clipped(Plane{normalized(Vec3{1, 1, 1}), 2.5}));
    for (int k = 0; k < 40; ++k) {
        std::vector<Vec3> points;
        for (int i = 0; i < 8 + k; ++i)
            points.push_back({rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)});
        auto hull = convexHull(points);
        ASSERT_TRUE(hull);
        parts.push_back(std::move(hull).value());
    }
    double worstShare = 1;
    for (const ConvexPolytope& part : parts) {
        const double margin = 0.02;
        const ConvexPolytope reference = clippedCore(part, margin);
        const std::vector<Vec3> core = CollisionShape::coreCorners(part, margin);
        ASSERT_GE(core.size(), 4u);
        for (const Vec3& c : core) // never outside: hull + margin stays in the part
            EXPECT_TRUE(reference.contains(c, 1e-9));
        auto coreHull = convexHull(core);
        ASSERT_TRUE(coreHull);
        worstShare = std::min(worstShare, coreHull->volume() / reference.volume());
    }
    EXPECT_EQ(CollisionShape::coreCorners(parts[0], 0.02).size(), 8u);
    EXPECT_GT(worstShare, 0.99); // and it misses little (only near faces narrower than the margin)
    // Thinner than twice the margin: nothing left.
    EXPECT_TRUE(
        CollisionShape::coreCorners(ConvexPolytope::fromAabb(Aabb{{0, 0, 0}, {1, 1, 0.03}}), 0.02).empty());
}

// A corner on more faces than the corner triples are tried for (a cone's apex on 40): the core comes from the
// polar of the moved-in planes instead of 41 clips, and is the clipped core up to rounding.
TEST(CollisionShape, ACornerOnManyFacesGivesTheCoreOfTheMovedInPlanes) {
    std::vector<Vec3> points{{0, 2, 0}};
    for (int i = 0; i < 40; ++i) {
        const double a = 2 * 3.14159265358979323846 * i / 40;
        points.push_back({std::cos(a), 0, std::sin(a)});
    }
    auto cone = convexHull(points);
    ASSERT_TRUE(cone);
    std::size_t atApex = 0;
    for (const PolytopeFaceView& f : cone->faces())
        for (const Vec3& c : f.corners)
            atApex += c == points[0];
    ASSERT_GT(atApex, 24u);
    const double margin = 0.04;
    ConvexPolytope reference = *cone;
    for (const PolytopeFaceView& f : cone->faces())
        reference = reference.clipped(Plane{f.plane.normal, f.plane.offset - margin});
    const std::vector<Vec3> core = CollisionShape::coreCorners(*cone, margin);
    ASSERT_GE(core.size(), 4u);
    for (const Vec3& c : core)
        EXPECT_TRUE(reference.contains(c, 1e-9));
    auto coreHull = convexHull(core);
    ASSERT_TRUE(coreHull);
    EXPECT_NEAR(coreHull->volume() / reference.volume(), 1.0, 1e-6);
}

// The debug edges are the parts' polygon edges in body coordinates, each corner held once, and every hull
// holds exactly its points.
TEST(CollisionShape, EdgesShareTheirCornersAndHullsHoldTheirPoints) {
    const ConvexPolytope part =
        ConvexPolytope::fromAabb(Aabb{{0, 0, 0}, {2, 1, 4}})
            .clipped(Plane{normalized(Vec3{1, 1, 1}), 3.5}); // a box with a corner cut
    Frame objectToBody{Mat3::identity(), {1, 0.5, 2}};       // turned by 0.4 rad about z
    objectToBody.rotation.m[0][0] = objectToBody.rotation.m[1][1] = std::cos(0.4);
    objectToBody.rotation.m[1][0] = std::sin(0.4);
    objectToBody.rotation.m[0][1] = -std::sin(0.4);
    auto shape = CollisionShape::fromParts({part}, {}, objectToBody, 0.05);
    ASSERT_TRUE(shape);
    std::vector<std::array<Vec3, 2>>
        expected; // each polygon edge once, from its lexicographically smaller end
    auto less = [](const Vec3& a, const Vec3& b) {
        return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
    };
    auto toBody = [&](const Vec3& p) { // kept in float
        return Vec3(Vec3f(objectToBody.rotation.transposed() * (p - objectToBody.translation)));
    };
    for (const PolytopeFaceView& f : part.faces())
        for (std::size_t i = 0; i < f.corners.size(); ++i) {
            const Vec3& a = f.corners[i];
            const Vec3& c = f.corners[(i + 1) % f.corners.size()];
            if (less(a, c))
                expected.push_back({toBody(a), toBody(c)});
        }
    const std::size_t corners = part.vertices().size();
    ASSERT_EQ(expected.size(), corners + part.faces().size() - 2); // Euler: E = V + F - 2
    EXPECT_EQ(shape->edges(), expected);
    EXPECT_EQ(shape->edgeCount(), expected.size());
    const CollisionShape::Bytes bytes = shape->bytes();
    EXPECT_EQ(bytes.edges, corners * sizeof(Vec3f) + expected.size() * 2 * sizeof(std::uint32_t));
    auto* hull = static_cast<btConvexHullShape*>(shape->shape());
    EXPECT_EQ(bytes.points, static_cast<std::size_t>(hull->getNumPoints()));
    EXPECT_EQ(bytes.points, corners); // the eroded hull keeps the part's combinatorics here
}

// A part's hull capped at 16 points lies inside the full one (a resting piece sinks, it never floats) and
// its support in any direction falls short of the full hull's by at most a tenth of its width, on a round
// rock, the worst case of a cap.
TEST(CollisionShape, ACappedHullLiesInsideTheFullOneAndKeepsItsSupport) {
    Rng rng(11);
    ConvexPolytope rock = ConvexPolytope::fromAabb(Aabb{{-1, -0.6, -0.8}, {1, 0.6, 0.8}});
    for (int i = 0; i < 30; ++i)
        rock = rock.clipped(Plane{rng.unitVector(), 0.55});
    const auto full = CollisionShape::fromParts({rock}, {}, Frame{}, 0.02);
    const auto capped = CollisionShape::fromParts({rock}, {}, Frame{}, 0.02, 16);
    ASSERT_TRUE(full && capped);
    auto* fullHull = static_cast<btConvexHullShape*>(full->shape());
    auto* cappedHull = static_cast<btConvexHullShape*>(capped->shape());
    ASSERT_GT(fullHull->getNumPoints(), 32);
    EXPECT_EQ(cappedHull->getNumPoints(), 16);
    EXPECT_EQ(cappedHull->getMargin(), fullHull->getMargin());
    double worst = 0;
    for (int i = 0; i < 2000; ++i) {
        const btVector3 d = toBt(rng.unitVector());
        const double f = d.dot(fullHull->localGetSupportingVertexWithoutMargin(d));
        const double c = d.dot(cappedHull->localGetSupportingVertexWithoutMargin(d));
        EXPECT_LE(c, f + 1e-6) << "inside the full hull";
        worst = std::max(worst, f - c);
    }
    std::printf("capped hull: support falls short by at most %.4f (of a %.2f-wide piece)\n", worst,
                rock.bounds().size().x);
    EXPECT_LT(worst, 0.12);
}

TEST(CollisionShape, SeveralPartsMakeACompound) {
    const ConvexPolytope a = ConvexPolytope::fromAabb(Aabb{{0, 0, 0}, {1, 1, 1}});
    const ConvexPolytope b = ConvexPolytope::fromAabb(Aabb{{1, 0, 0}, {2, 1, 1}});
    auto shape = CollisionShape::fromParts({a, b}, {}, Frame{}, 0.02);
    ASSERT_TRUE(shape);
    EXPECT_EQ(shape->childCount(), 2);
    ASSERT_EQ(shape->shape()->getShapeType(), COMPOUND_SHAPE_PROXYTYPE);
    EXPECT_EQ(static_cast<btCompoundShape*>(shape->shape())->getNumChildShapes(), 2);
}

TEST(CollisionShape, ThinPartsStillGetAHull) {
    const ConvexPolytope sliver = ConvexPolytope::fromAabb(Aabb{{0, 0, 0}, {1, 1, 0.001}});
    auto shape = CollisionShape::fromParts({sliver}, {}, Frame{}, 0.05);
    ASSERT_TRUE(shape);
    EXPECT_EQ(shape->childCount(), 1);
}

TEST(CollisionShape, FallsBackToTheHullOfPointsWithoutParts) {
    const Mesh sphere = makeSphere({0, 0, 0}, 1, 24, 12);
    auto shape = CollisionShape::fromParts({}, sphere.positions, Frame{}, 0.02);
    ASSERT_TRUE(shape);
    EXPECT_EQ(shape->childCount(), 1);
    EXPECT_FALSE(CollisionShape::fromParts({}, {{0, 0, 0}, {1, 0, 0}}, Frame{}, 0.02));
}

TEST(PhysicsWorld, StepsInFixedSubSteps) {
    PhysicsWorld::Config c;
    c.maxSubSteps = 3;
    PhysicsWorld world(c);
    int post = 0;
    world.setPostTickCallback([&](double) { ++post; });
    EXPECT_EQ(world.step(1.0 / 60), 1);
    EXPECT_EQ(post, 1);
    EXPECT_EQ(world.step(1.0), 3);
    EXPECT_EQ(post, 4);
    EXPECT_EQ(world.ticks(), 4);
}

// An L-shaped solid of two boxes, built with its body at the true centre of mass, rests on the ground with
// its centre of mass where the geometry says (the thesis placed bodies at the bounding-box centre instead).
TEST(PhysicsWorld, BodyAtCentreOfMassRestsCorrectly) {
    PhysicsWorld world;
    auto groundShape = CollisionShape::box({50, 0.5, 50});
    btRigidBody::btRigidBodyConstructionInfo gi(0, nullptr, groundShape->shape());
    gi.m_startWorldTransform.setIdentity();
    gi.m_startWorldTransform.setOrigin({0, -0.5f, 0});
    btRigidBody ground(gi);
    world.world().addRigidBody(&ground);

    const std::vector<ConvexPolytope> parts{ConvexPolytope::fromAabb(Aabb{{0, 0, 0}, {3, 1, 1}}),
                                            ConvexPolytope::fromAabb(Aabb{{0, 1, 0}, {1, 3, 1}})};
    Mesh mesh = parts[0].toMesh();
    mesh.append(parts[1].toMesh());
    const MassProperties mp = computeMassProperties(mesh);
    const Frame objectToBody{mp.principalAxes, mp.centerOfMass};
    auto shape = CollisionShape::fromParts(parts, {}, objectToBody, 0.02);
    ASSERT_TRUE(shape);
    const double density = 2;
    const btVector3 inertia = toBt(mp.principalMoments * density);
    btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(density * mp.volume), nullptr,
                                                  shape->shape(), inertia);
    info.m_startWorldTransform = toBt(Frame{Mat3::identity(), {0, 0.01, 0}}) * toBt(objectToBody);
    btRigidBody body(info);
    world.world().addRigidBody(&body);
    for (int i = 0; i < 120; ++i)
        world.step(1.0 / 60);
    // resting upright: the centre of mass is where the mesh says, the L did not tip over
    const Vec3 com = fromBt(body.getCenterOfMassPosition());
    EXPECT_NEAR(com.x, mp.centerOfMass.x, 0.05);
    EXPECT_NEAR(com.y, mp.centerOfMass.y, 0.05);
    EXPECT_NEAR(com.z, mp.centerOfMass.z, 0.05);
    EXPECT_LT(body.getLinearVelocity().length(), 0.05f);
    world.world().removeRigidBody(&body);
    world.world().removeRigidBody(&ground);
}
