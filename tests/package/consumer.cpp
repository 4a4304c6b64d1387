// A game's first contact with an installed Rubble: fracture a mesh with the kernel (also as a request), then
// let Bullet and the runtime break a cube hit by a projectile, then ask the engine-free structure what
// stands. Exits non-zero when volume is not conserved, nothing breaks or the wrong body falls.
#include <cmath>
#include <cstdio>

#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/rubble.hpp"
#include "rubble/runtime/Structure.hpp"

namespace {

bool near(double a, double b, double relative) {
    return std::abs(a - b) <= relative * std::abs(b);
}

} // namespace

int main() {
    const rubble::Mesh cube = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 4);

    // 1. The kernel.
    rubble::Impact impact;
    impact.point = {0.3, 1.0, 0.2};
    impact.normal = {0, 1, 0};
    impact.impulse = 40;
    const rubble::Result<rubble::FractureResult> broken = rubble::fracture(cube, impact, {}, 7);
    if (!broken) {
        std::fprintf(stderr, "fracture failed: %s\n", broken.error().message.c_str());
        return 1;
    }
    double volume = broken->droppedVolume;
    for (const rubble::Piece& piece : broken->pieces)
        volume += piece.mass.volume;
    std::printf("kernel: %zu pieces, volume %.9f of %.9f\n", broken->pieces.size(), volume,
                broken->inputVolume);
    if (broken->pieces.size() < 2 || !near(volume, broken->inputVolume, 1e-9))
        return 1;
    // The same fracture as a request: the same pieces.
    rubble::FractureRequest request;
    request.mesh = &cube;
    request.impact = impact;
    request.seed = 7;
    const rubble::Result<rubble::FractureResult> requested = rubble::fracture(request);
    if (!requested || requested->pieces.size() != broken->pieces.size() ||
        requested->pieces.front().mesh.hash() != broken->pieces.front().mesh.hash()) {
        std::fprintf(stderr, "fracture(FractureRequest) differs from fracture(mesh, impact, params, seed)\n");
        return 1;
    }

    // 2. The runtime over Bullet: a static cube on the ground, a projectile fired at it.
    rubble::bullet::PhysicsWorld physics;
    rubble::bullet::BulletBinding binding(physics);
    rubble::DestructionRuntime::Config config;
    config.world.workers = 1;
    rubble::DestructionRuntime runtime(binding, config);
    runtime.addGround({0, -0.5, 0}, {20, 0.5, 20});
    rubble::ObjectDesc desc;
    desc.mesh = cube;
    desc.impulseThreshold = 1;
    const rubble::Result<rubble::ObjectId> object =
        runtime.addObject(desc, rubble::Frame{rubble::Mat3::identity(), {0, 1, 0}}, true);
    if (!object) {
        std::fprintf(stderr, "addObject failed: %s\n", object.error().message.c_str());
        return 1;
    }
    const double before = runtime.volumes().total();
    runtime.fireProjectile({0, 1.2, -8}, {0, 0, 60}, 5, 0.2);
    int frames = 0;
    while (runtime.counters().fractures == 0 && frames < 240) {
        runtime.stepFrame();
        ++frames;
        if (runtime.counters().impacts > 0)
            runtime.world().waitIdle(); // a game would go on rendering meanwhile
    }
    for (int i = 0; i < 30; ++i) // let the pieces fall
        runtime.stepFrame();
    const double after = runtime.volumes().total();
    std::printf("runtime: %lld fractures after %d frames, %zu bodies, volume %.9f of %.9f\n",
                static_cast<long long>(runtime.counters().fractures), frames, runtime.bodyCount(), after,
                before);
    if (runtime.counters().fractures == 0 || !near(after, before, 1e-6))
        return 1;

    // 3. The structure without an engine: a box on the held ground stands, a box in the air falls.
    rubble::Structure structure;
    const rubble::Frame here{rubble::Mat3::identity(), {}};
    const bool added =
        structure.add(1, rubble::makeSubdividedBox({-5, -1, -5}, {5, 0, 5}, 1), here, "", true) &&
        structure.add(2, rubble::makeSubdividedBox({-1, 0, -1}, {1, 1, 1}, 1), here, "brick") &&
        structure.add(3, rubble::makeSubdividedBox({-1, 3, -1}, {1, 4, 1}, 1), here, "brick");
    const rubble::StructureStep step = structure.step();
    std::printf("structure: %zu bodies, %zu collapsed, residual %.2g\n", structure.size(),
                step.collapses.size(), step.residual);
    return added && step.collapses.size() == 1 && step.collapses[0].body == 3 && structure.size() == 2 ? 0
                                                                                                       : 1;
}
