// HelloWorld: see docs/hello.md. Breaks a cube twice: once with the fracture kernel directly, once through
// the engine-agnostic runtime a game uses (impacts in, pieces with collision parts out, work off the main
// thread).
#include <cstdio>

#include "rubble/rubble.hpp"

int main() {
    // 1. A mesh is a value type: a closed 2 m cube of 588 triangles.
    const rubble::Mesh cube = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 7);

    // 2. The fracture kernel: hit the top face, get the damaged cube and the debris as closed meshes.
    rubble::Impact impact;
    impact.point = {0.3, 1.0, 0.2}; // on the top face, in the mesh's coordinates
    impact.normal = {0, 1, 0};      // surface normal at the hit
    impact.impulse = 40;            // N·s: bigger impulses cut bigger cells (FractureParams::sizeLaw)
    rubble::FractureParams params;  // defaults: the thesis's single Voronoi cell
    const rubble::Result<rubble::FractureResult> broken = rubble::fracture(cube, impact, params, /*seed=*/7);
    if (!broken) { // errors are data, never exceptions
        std::fprintf(stderr, "fracture failed: %s\n", broken.error().message.c_str());
        return 1;
    }
    double total = 0;
    for (const rubble::Piece& piece : broken->pieces) {
        std::printf("piece %s: %zu triangles, volume %.4f, centre of mass (%.3f, %.3f, %.3f)\n",
                    piece.cell < 0 ? "remainder" : "debris   ", piece.mesh.triangleCount(), piece.mass.volume,
                    piece.mass.centerOfMass.x, piece.mass.centerOfMass.y, piece.mass.centerOfMass.z);
        total += piece.mass.volume;
    }
    std::printf("volume before %.6f, after %.6f, in %.2f ms\n", broken->inputVolume, total,
                broken->stats.timings.totalMs);

    // 3. The runtime: what a game links. It decomposes the object into convex parts once, fractures on a
    //    worker thread, and hands out pieces (with their convex parts and frames) for adoption.
    rubble::DestructionWorld world(rubble::DestructionWorld::Config{});
    rubble::ObjectDesc desc;
    desc.mesh = cube;
    desc.impulseThreshold = 10; // resting contacts below this never break it
    const rubble::Result<rubble::ObjectId> id = world.addObject(std::move(desc));
    if (!id) {
        std::fprintf(stderr, "addObject failed: %s\n", id.error().message.c_str());
        return 1;
    }
    world.submitImpact(*id, impact); // e.g. from a contact callback of your physics engine
    world.waitIdle();                // a game instead calls beginFrame() + collect() once per frame
    world.beginFrame();
    for (const rubble::FractureOutcome& outcome : world.collect()) {
        std::printf("object %u broke into %zu pieces:\n", outcome.parent, outcome.pieces.size());
        for (const rubble::AdoptedPiece& adopted : outcome.pieces) {
            const rubble::ObjectState* piece = adopted.state.get();
            const rubble::Vec3 at = adopted.frame.translation; // where its body goes (centre of mass)
            std::printf("  id %u: volume %.4f, %zu convex parts, body at (%.3f, %.3f, %.3f)\n", piece->id,
                        piece->mass.volume, piece->convexParts.size(), at.x, at.y, at.z);
        }
        world.commit(outcome); // the pieces' bodies exist: the pieces replace the parent in the world
    }
    const double conserved = total - broken->inputVolume;
    return broken->pieces.size() >= 2 && conserved * conserved < 1e-12 ? 0 : 1;
}
