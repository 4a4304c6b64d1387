// The runtime row of the million-triangle bench, run by `rubble-bench impact --mega --world`:
// the kernel row's meshes and hit points through a DestructionRuntime on the Bullet binding. Each hit lands
// on a fresh static object (added untimed, with the kernel row's convex parts); the stages are those of the
// world's TimingRecord, the main thread's adoption is timed around adoptReady(), and the binding's shape
// update is timed again by building the new pieces' collision shapes (CollisionShape::fromParts).
#include <fstream>
#include <iostream>
#include <sstream>

#include <malloc.h>
#include <unistd.h>

#include "BenchUtil.hpp"
#include "MegaMeshes.hpp"

#ifdef RUBBLE_HAVE_BULLET
#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/CollisionShape.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#endif

namespace rubble::bench {

double residentMb() {
    std::ifstream in("/proc/self/statm");
    long pages = 0, resident = 0;
    in >> pages >> resident;
    return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

// Bytes the heap holds in use (freed blocks that malloc keeps are not counted, unlike in resident memory).
double heapInUseMb() {
    const struct mallinfo2 m = mallinfo2();
    return static_cast<double>(m.uordblks + m.hblkhd) / (1024.0 * 1024.0);
}

std::vector<std::string> worldRowHeader() {
    return {"mesh",
            "triangles",
            "hits",
            "failures",
            "kernel_median_ms",
            "world_median_ms",
            "world_max_ms",
            "world_over_kernel",
            "queue_median_ms",
            "prepare_median_ms",
            "cell_median_ms",
            "boolean_median_ms",
            "islands_median_ms",
            "decomposition_median_ms",
            "finish_median_ms",
            "handoff_median_ms",
            "adoption_median_ms",
            "main_adopt_median_ms",
            "shapes_median_ms",
            "pieces_median",
            "object_rss_mb",
            "object_heap_mb",
            "heap_bytes_per_triangle",
            "other_cpu_cores"};
}

#ifdef RUBBLE_HAVE_BULLET
bool addWorldRow(const std::string& name, const Mesh& mesh, const std::vector<ConvexPolytope>& parts,
                 const FractureParams& params, const std::vector<Impact>& hits, double kernelMedianMs,
                 Table& table, Table& csv) {
    using namespace rubble::bullet;
    PhysicsWorld physics;
    BulletBinding binding(physics);
    DestructionRuntime::Config rc;
    rc.world.workers = 1;
    rc.world.adoptionBudgetMs = 1e9;
    DestructionRuntime runtime(binding, rc);
    std::vector<double> total, queue, prepare, cell, boolean, islands, decomposition, finish, handoff,
        adoption, mainAdopt, shapes, pieces;
    double objectMb = 0, objectHeapMb = 0;
    int failures = 0;
    for (const Impact& hit : hits) {
        const double before = residentMb(), heapBefore = heapInUseMb(); // the copy below is the object's
        ObjectDesc desc;
        desc.mesh = mesh;
        desc.convexParts = parts;
        desc.fracture = params;
        auto id = runtime.addObject(std::move(desc), Frame{}, true);
        if (!id) {
            std::cerr << name << ": " << id.error().message << "\n";
            return false;
        }
        objectMb = std::max(objectMb, residentMb() - before);
        objectHeapMb = std::max(objectHeapMb, heapInUseMb() - heapBefore);
        const BodyId body = runtime.bodyOf(*id)->id;
        const std::size_t records = runtime.world().timings().size();
        if (!runtime.submitImpact(body, hit.point, hit.normal, hit.impulse)) {
            ++failures;
            continue;
        }
        runtime.world().waitIdle();
        const auto t0 = std::chrono::steady_clock::now();
        runtime.adoptReady();
        const double mainMs = msSince(t0);
        const auto& timings = runtime.world().timings();
        if (timings.size() == records || timings.back().pieces == 0) {
            ++failures;
        } else {
            const TimingRecord& r = timings.back();
            total.push_back(r.totalMs);
            queue.push_back(r.queueMs);
            prepare.push_back(r.prepareMs);
            cell.push_back(r.cellMs);
            boolean.push_back(r.booleanMs);
            islands.push_back(r.islandsMs);
            decomposition.push_back(r.decompositionMs);
            finish.push_back(r.finishMs);
            handoff.push_back(r.handoffMs);
            adoption.push_back(r.adoptionMs);
            mainAdopt.push_back(mainMs);
            pieces.push_back(r.pieces);
            // the binding's part of adoption, again: the new bodies' collision shapes
            const auto s0 = std::chrono::steady_clock::now();
            for (BodyId b : runtime.bodies())
                if (const BodyRecord* rec = runtime.body(b); rec && rec->hasObject)
                    if (const ObjectState* st = runtime.world().object(rec->object)) {
                        std::vector<ConvexPolytope> local;
                        for (const ConvexPolytope& p : st->convexParts)
                            local.push_back(p.transformed(rec->objectToBody.inverse()));
                        (void)CollisionShape::fromParts(local, {}, Frame{}, 0.04);
                    }
            shapes.push_back(msSince(s0));
        }
        for (BodyId b : runtime.bodies())
            runtime.removeBody(b);
    }
    const auto med = [](const std::vector<double>& v) { return stats(v).median; };
    const Stats w = stats(total);
    const double ratio = kernelMedianMs > 0 ? w.median / kernelMedianMs : -1;
    const double bytesPerTriangle = objectHeapMb * 1024 * 1024 / static_cast<double>(mesh.triangles.size());
    table.rows.push_back({name + " world", std::to_string(mesh.triangles.size()),
                          std::to_string(total.size()), fixed(kernelMedianMs), fixed(w.median), fixed(w.max),
                          fixed(ratio, 2), fixed(med(prepare)), fixed(med(boolean)), fixed(med(islands)),
                          fixed(med(decomposition)), fixed(med(finish)), fixed(med(adoption)),
                          fixed(med(shapes)), fixed(bytesPerTriangle, 0)});
    std::vector<std::string> row{name,
                                 std::to_string(mesh.triangles.size()),
                                 std::to_string(total.size()),
                                 std::to_string(failures),
                                 fixed(kernelMedianMs),
                                 fixed(w.median),
                                 fixed(w.max),
                                 fixed(ratio, 3)};
    for (const auto* v : {&queue, &prepare, &cell, &boolean, &islands, &decomposition, &finish, &handoff,
                          &adoption, &mainAdopt, &shapes})
        row.push_back(fixed(med(*v)));
    row.insert(row.end(), {fixed(med(pieces), 0), fixed(objectMb, 1), fixed(objectHeapMb, 1),
                           fixed(bytesPerTriangle, 0), ""});
    csv.rows.push_back(std::move(row));
    std::cout << name << " in the world: median " << fixed(w.median) << " ms (" << fixed(ratio, 2)
              << "x the kernel's " << fixed(kernelMedianMs) << "), finish " << fixed(med(finish))
              << " ms, object " << fixed(objectHeapMb, 1) << " MB in use (" << fixed(objectMb, 1)
              << " MB resident)" << std::endl;
    return true;
}
#else
bool addWorldRow(const std::string& name, const Mesh&, const std::vector<ConvexPolytope>&,
                 const FractureParams&, const std::vector<Impact>&, double, Table&, Table&) {
    std::cerr << name << ": the world row needs the Bullet binding (RUBBLE_BUILD_BULLET)\n";
    return false;
}
#endif

} // namespace rubble::bench
