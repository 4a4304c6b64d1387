// `rubble-bench memory [--pieces N...] [--triangles N] [--large-kinds K...] [--attributes] [--quick]
//  [--label TEXT] [--out DIR]`
//
// What the world holds per debris piece and per triangle of a large object, on the Bullet binding.
// Pieces: a facade (assets/models/facade_x.obj, with normals and UVs) is shattered through a
// DestructionRuntime until a few hundred debris pieces are adopted; those pieces are the templates. Then, for
// each N, a fresh runtime gets N dynamic objects, each a template's mesh and convex parts on a grid, and the
// heap in use (mallinfo2) before and after gives bytes per piece; the live containers give the split (mesh
// arrays, convex parts, the binding's hulls and edges, bodies; the rest is bookkeeping and allocator
// headers). The templates as adopted are measured too (their arrays' spare capacity included). Large
// objects: each --large-kinds mesh (a geodesic sphere, the arch) of --triangles triangles added static
// (decomposed on add); the work arrays that the thread checking a mesh keeps for the next one are reported
// apart (thread scratch). Table on stdout, memory.csv and memory.png in DIR (rows of another --label already
// in memory.csv stay, so that a before and an after run share one file).
#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "BenchUtil.hpp"
#include "MegaMeshes.hpp"
#include "Subcommand.hpp"
#include "rubble/io/MeshIO.hpp"

#ifdef RUBBLE_HAVE_BULLET
#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/CollisionShape.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#endif

namespace {

namespace fs = std::filesystem;
using rubble::bench::fixed;

struct BenchArgs {
    std::vector<int> pieces{10000, 40000};
    std::size_t triangles = 1000000;
    std::vector<std::string> kinds{"geosphere", "arch"};
    bool attributes = false;
    bool quick = false;
    std::string label = "current";
    std::string out = rubble::bench::resultsDir();
};

#ifdef RUBBLE_HAVE_BULLET
using namespace rubble;
using namespace rubble::bullet;

double heapInUseBytes() {
    const struct mallinfo2 m = mallinfo2();
    return static_cast<double>(m.uordblks + m.hblkhd);
}

template <class T>
double capacityBytes(const std::vector<T>& v) {
    return static_cast<double>(v.capacity() * sizeof(T));
}

// Bytes of the live pieces' containers, summed over every body that carries a world object.
struct Split {
    double positions = 0, triangles = 0, normals = 0, uvs = 0, materials = 0;
    double parts = 0;                     // convex parts: faces, corners and corner indices
    double hulls = 0, edges = 0;          // the binding's collision shapes and debug edges
    double bodies = 0;                    // rigid bodies and the binding's entries
    double spare = 0;                     // of the mesh arrays above, capacity beyond size
    double meshTriangles = 0, parts_ = 0; // counts: triangles and convex parts
    double hullPoints = 0;
    std::size_t pieces = 0;
    double accounted() const {
        return positions + triangles + normals + uvs + materials + parts + hulls + edges + bodies;
    }
};

template <class T>
double spareBytes(const std::vector<T>& v) {
    return static_cast<double>((v.capacity() - v.size()) * sizeof(T));
}

Split split(const DestructionRuntime& runtime, const BulletBinding& binding, bool piecesOnly) {
    Split s;
    for (BodyId id : runtime.bodies()) {
        const BodyRecord* rec = runtime.body(id);
        if (!rec || !rec->hasObject || (piecesOnly && rec->role != BodyRole::Piece))
            continue;
        const ObjectState* o = runtime.world().object(rec->object);
        if (!o)
            continue;
        ++s.pieces;
        const Mesh& m = o->mesh;
        s.positions += capacityBytes(m.positions);
        s.triangles += capacityBytes(m.triangles);
        s.normals += capacityBytes(m.normals);
        s.uvs += capacityBytes(m.uvs);
        s.materials += capacityBytes(m.materials);
        s.spare += spareBytes(m.positions) + spareBytes(m.triangles) + spareBytes(m.normals) +
                   spareBytes(m.uvs) + spareBytes(m.materials);
        s.meshTriangles += static_cast<double>(m.triangles.size());
        s.parts += capacityBytes(o->convexParts);
        for (const ConvexPolytope& p : o->convexParts)
            s.parts += static_cast<double>(p.heapBytes());
        s.parts_ += static_cast<double>(o->convexParts.size());
        if (const CollisionShape* shape = binding.shape(id)) {
            const CollisionShape::Bytes b = shape->bytes();
            s.hulls += static_cast<double>(b.shapes);
            s.edges += static_cast<double>(b.edges);
            s.hullPoints += static_cast<double>(b.points);
        }
        s.bodies += static_cast<double>(sizeof(btRigidBody) + sizeof(btBroadphaseProxy) + 64);
    }
    return s;
}

FractureParams shatter() {
    FractureParams p;
    p.pattern = CellPattern::Shatter;
    p.cells = 16;
    return p;
}

// A runtime on Bullet with one fracture worker and no adoption budget.
struct Rig {
    static DestructionRuntime::Config config() {
        DestructionRuntime::Config c;
        c.world.workers = 1;
        c.world.adoptionBudgetMs = 1e9;
        return c;
    }
    PhysicsWorld physics;
    BulletBinding binding{physics};
    DestructionRuntime runtime{binding, config()};
};

// Debris pieces as the runtime adopts them: the facade shattered until `want` pieces are live.
struct Templates {
    std::vector<ObjectDesc> descs;
    Split adopted; // the adopted pieces' containers
    // heap growth over the fractures per live piece (remainders and records included)
    double heapPerPiece = 0;
};

Templates makeTemplates(std::size_t want) {
    Templates t;
    auto mesh = readObj(rubble::bench::sourceDir() / "assets/models/facade_x.obj");
    if (!mesh) {
        std::cerr << "memory: " << mesh.error().message << "\n";
        return t;
    }
    Rig rig;
    DestructionRuntime& runtime = rig.runtime;
    BulletBinding& binding = rig.binding;
    const double heap0 = heapInUseBytes();
    ObjectDesc desc;
    desc.mesh = std::move(*mesh);
    desc.fracture = shatter();
    if (!runtime.addObject(std::move(desc), Frame{}, true)) {
        std::cerr << "memory: the facade was refused\n";
        return t;
    }
    for (int round = 0; round < 400 && static_cast<std::size_t>(runtime.livePieces()) < want; ++round) {
        BodyId target = 0; // the largest object left (pieces of pieces, as in a demolition)
        double volume = 0;
        for (BodyId id : runtime.bodies())
            if (const BodyRecord* r = runtime.body(id); r && r->hasObject && r->volume > volume)
                target = id, volume = r->volume;
        if (volume == 0)
            break;
        const BodyMotion m = runtime.motion(target);
        const double s = 0.37 * round;
        const Vec3 offset{std::sin(s) * 1.5, std::cos(1.3 * s) * 1.0, 0};
        if (runtime.submitImpact(target, m.transform.translation + offset, Vec3{0, 0, 1}, 4000)) {
            runtime.world().waitIdle();
            runtime.adoptReady();
        }
    }
    t.adopted = split(runtime, binding, true);
    t.heapPerPiece =
        (heapInUseBytes() - heap0) / static_cast<double>(std::max<std::size_t>(1, t.adopted.pieces));
    for (BodyId id : runtime.bodies())
        if (const BodyRecord* r = runtime.body(id); r && r->hasObject && r->role == BodyRole::Piece)
            if (const ObjectState* o = runtime.world().object(r->object)) {
                ObjectDesc d;
                d.mesh = o->mesh;
                d.convexParts = o->convexParts;
                d.fracture = o->fracture;
                t.descs.push_back(std::move(d));
            }
    return t;
}

struct Row {
    std::string name;
    std::size_t count = 0; // pieces, or triangles of the large object
    double heapBytes = 0;  // heap growth
    double worldBytes = 0; // heap growth of a DestructionWorld alone given the same objects
    double scratch = 0;    // kept by the thread that checked the mesh (the first large add only)
    double residentMb = 0; // resident growth
    Split s;
    double seconds = 0;
};

// Heap growth of a DestructionWorld alone (no runtime, no engine) given these objects.
double worldOnlyBytes(const std::vector<ObjectDesc>& descs, std::size_t n) {
    DestructionWorld::Config c;
    c.workers = 1;
    DestructionWorld world(c);
    const double heap0 = heapInUseBytes();
    for (std::size_t i = 0; i < n; ++i)
        (void)world.addObject(descs[i % descs.size()]);
    return heapInUseBytes() - heap0;
}

// Heap growth and its split while `add` runs on a fresh rig.
template <class Add>
bool measure(Row& row, Add&& add) {
    Rig rig;
    const auto t0 = std::chrono::steady_clock::now();
    const double heap0 = heapInUseBytes(), rss0 = rubble::bench::residentMb();
    if (!add(rig.runtime))
        return false;
    row.heapBytes = heapInUseBytes() - heap0;
    row.residentMb = rubble::bench::residentMb() - rss0;
    row.seconds = rubble::bench::msSince(t0) / 1000;
    row.s = split(rig.runtime, rig.binding, false);
    return true;
}

Row piecesRow(const Templates& t, int n) {
    Row row;
    row.name = "pieces_" + std::to_string(n);
    row.count = static_cast<std::size_t>(n);
    row.worldBytes = worldOnlyBytes(t.descs, row.count);
    const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n))));
    measure(row, [&](DestructionRuntime& runtime) {
        for (int i = 0; i < n; ++i) {
            ObjectDesc d = t.descs[static_cast<std::size_t>(i) % t.descs.size()];
            Frame placement;
            placement.translation =
                Vec3{3.0 * (i % side), 3.0 * ((i / side) % side), 3.0 * (i / (side * side))};
            if (!runtime.addObject(std::move(d), placement, false)) {
                std::cerr << "memory: piece " << i << " was refused\n";
                return false;
            }
        }
        return true;
    });
    return row;
}

// The mesh with per-corner flat normals and planar texture coordinates, as an OBJ asset brings them.
Row largeRow(const std::string& kind, std::size_t triangles, bool attributes) {
    Row row;
    const Mesh mesh = attributes ? rubble::bench::withFlatAttributes(rubble::bench::megaMesh(kind, triangles))
                                 : rubble::bench::megaMesh(kind, triangles);
    row.name = kind + "_" + std::to_string(mesh.triangles.size()) + (attributes ? "_attributes" : "");
    row.count = mesh.triangles.size();
    {
        ObjectDesc d;
        d.mesh = mesh;
        d.fracture = shatter();
        // the first add of the largest mesh so far also grows the calling thread's kept work arrays
        // (closedOrientedShells); the second measures the object alone
        const double first = worldOnlyBytes({d}, 1);
        row.worldBytes = worldOnlyBytes({d}, 1);
        row.scratch = first - row.worldBytes;
    }
    measure(row, [&](DestructionRuntime& runtime) {
        ObjectDesc d;
        d.mesh = mesh; // the object's own copy is counted
        d.fracture = shatter();
        if (!runtime.addObject(std::move(d), Frame{}, true)) {
            std::cerr << "memory: the large object was refused\n";
            return false;
        }
        return true;
    });
    return row;
}

std::vector<std::string> csvRow(const std::string& label, const Row& r, double otherCpu) {
    const double n = static_cast<double>(std::max<std::size_t>(1, r.count));
    const double pieces = static_cast<double>(std::max<std::size_t>(1, r.s.pieces));
    const Split& s = r.s;
    std::vector<std::string> row{label, r.name, std::to_string(r.count)};
    for (double v : {r.heapBytes, r.worldBytes, r.scratch})
        row.push_back(fixed(v / n, 1));
    row.insert(row.end(), {fixed(r.residentMb, 1), fixed(s.meshTriangles / pieces, 1),
                           fixed(s.parts_ / pieces, 2), fixed(s.hullPoints / pieces, 1)});
    for (double v : {s.positions, s.triangles, s.normals, s.uvs, s.materials, s.spare, s.parts, s.hulls,
                     s.edges, s.bodies, r.heapBytes - s.accounted()})
        row.push_back(fixed(v / n, 1));
    row.insert(row.end(), {fixed(r.seconds, 2), fixed(otherCpu, 2)});
    return row;
}

int runBench(const BenchArgs& args) {
    if (!rubble::bench::makeResultsDir(args.out))
        return 2;
    rubble::bench::CpuMeter cpu;
    const bool pieceRows = std::any_of(args.pieces.begin(), args.pieces.end(), [](int n) { return n > 0; });
    const Templates t = pieceRows ? makeTemplates(args.quick ? 20 : 300) : Templates{};
    if (pieceRows && t.descs.empty()) {
        std::cerr << "memory: no debris pieces to measure\n";
        return 1;
    }
    std::vector<Row> rows;
    if (pieceRows) {
        Row adopted;
        adopted.name = "adopted_" + std::to_string(t.adopted.pieces);
        adopted.count = t.adopted.pieces;
        adopted.heapBytes = t.heapPerPiece * static_cast<double>(t.adopted.pieces);
        adopted.s = t.adopted;
        rows.push_back(adopted);
    }
    for (int n : args.pieces) {
        if (n == 0)
            continue;
        rows.push_back(piecesRow(t, args.quick ? std::min(n, 200) : n));
        std::cout << rows.back().name << ": "
                  << fixed(rows.back().heapBytes / std::max(1.0, double(rows.back().count)), 0)
                  << " bytes per piece" << std::endl;
    }
    for (const std::string& kind : args.triangles > 0 ? args.kinds : std::vector<std::string>{}) {
        rows.push_back(largeRow(kind,
                                args.quick ? std::min<std::size_t>(args.triangles, 20000) : args.triangles,
                                args.attributes));
        std::cout << rows.back().name << ": "
                  << fixed(rows.back().heapBytes / std::max(1.0, double(rows.back().count)), 1)
                  << " bytes per triangle" << std::endl;
    }
    const double otherCpu = cpu.read().other;
    rubble::bench::Table csv{{"label",
                              "case",
                              "count",
                              "heap_bytes_per_unit",
                              "world_alone_bytes_per_unit",
                              "thread_scratch_bytes_per_unit",
                              "resident_growth_mb",
                              "triangles_per_piece",
                              "parts_per_piece",
                              "hull_points_per_piece",
                              "positions_b",
                              "triangles_b",
                              "normals_b",
                              "uvs_b",
                              "materials_b",
                              "spare_capacity_b",
                              "convex_parts_b",
                              "binding_hulls_b",
                              "binding_edges_b",
                              "bodies_b",
                              "other_b",
                              "seconds",
                              "other_cpu_cores"},
                             {}};
    // rows of other labels already in the file stay (a before and an after run side by side)
    const fs::path csvPath = fs::path(args.out) / "memory.csv";
    csv.rows = rubble::bench::rowsOfOtherLabels(csvPath, args.label, csv.header.size());
    for (const Row& r : rows)
        csv.rows.push_back(csvRow(args.label, r, otherCpu));
    rubble::bench::Table table{{"label", "case", "count", "B/unit", "world alone", "scratch", "tri/piece",
                                "positions", "triangles", "normals", "uvs", "spare", "parts", "hulls",
                                "edges", "bodies", "other"},
                               {}};
    for (const auto& c : csv.rows)
        table.rows.push_back({c[0], c[1], c[2], c[3], c[4], c[5], c[7], c[10], c[11], c[12], c[13], c[15],
                              c[16], c[17], c[18], c[19], c[20]});
    rubble::bench::printTable(table);
    std::cout << "(bytes per piece, or per triangle for the large object; other = heap growth not in the "
                 "columns: bookkeeping and allocator headers)\n";
    if (!rubble::bench::writeCsv(csvPath, csv))
        return 1;
    std::ostringstream data;
    int x = 0;
    for (const auto& c : csv.rows)
        if (c[1].rfind("pieces_", 0) == 0 || c[1].rfind("adopted_", 0) == 0) {
            std::string name = c[0] + " " + c[1];
            std::replace(name.begin(), name.end(), '_', ' '); // no subscripts in gnuplot's labels
            data << x++ << " \"" << name << "\" " << c[3] << " " << c[4] << "\n";
        }
    rubble::bench::plotPng(
        args.out, "memory", data.str(),
        "set style fill solid 0.6\nset boxwidth 0.6\nset ylabel 'heap bytes per piece'\n"
        "set grid y\nset yrange [0:*]\nset xtics rotate by -20\n"
        "set title 'Heap per debris piece in the world (Bullet binding)'\n"
        "plot $DATA u 1:3:xtic(2) w boxes title 'world, runtime and Bullet', "
        "$DATA u 1:4 w boxes title 'DestructionWorld alone', 8192 w l dt 2 title '8 KB target'");
    return 0;
}
#else
int runBench(const BenchArgs&) {
    std::cerr << "memory: needs the Bullet binding (RUBBLE_BUILD_BULLET)\n";
    return 1;
}
#endif

const rubble::tools::Registrar registrar{
    {"memory", "Heap bytes per debris piece and per triangle of a large object in the world",
     [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_option("--pieces", args->pieces, "debris pieces per row (0: none)")
             ->check(CLI::Range(0, 1000000));
         app.add_option("--triangles", args->triangles, "triangles of the large object (0: none)");
         app.add_option("--large-kinds", args->kinds, "meshes of the large-object rows")
             ->check(CLI::IsMember(rubble::bench::kMegaKinds));
         app.add_flag("--attributes", args->attributes,
                      "the large objects with per-corner normals and texture coordinates");
         app.add_flag("--quick", args->quick, "200 pieces and a 20k-triangle object (CI smoke run)");
         app.add_option("--label", args->label, "names this run's rows in memory.csv (e.g. before, after)");
         app.add_option("--out", args->out, "folder for memory.csv and memory.png");
         return [args] { return runBench(*args); };
     }}};

} // namespace
