// `rubble fracture MESH... --impact X,Y,Z [--impulse F] [--cells K] [--depth D] [--seed S]
//                  [--backend corefine|nef|fast] [--interior-texture IMAGE] -o DIR [--json] [--format
//                  obj|gltf]`
//
// Fractures closed meshes at an impact point (in each mesh's coordinates) like the runtime does: cells around
// the impact, booleans, islands, mass properties, then each piece's convex parts by the incremental update of
// the parent's decomposition. Writes DIR/piece_000.obj (+ .mtl, cut faces in the material "interior", convex
// parts as UCX_piece_000_NN objects) ... or, with --format gltf, DIR/pieces.gltf (one node per piece at its
// centre of mass, mass properties in its extras, convex parts as "-convcolonly" child nodes). Source
// materials and their textures are carried over (images copied into DIR/textures/). A multi-object input (a
// glTF node tree, an OBJ with several objects) is read as a scene: the leaf object containing the impact, or
// nearest to it, is fractured and the set is rewritten with the other objects unchanged. --depth D > 1
// fractures every piece again, level by level, into a glTF node tree with the bonds between sibling chunks in
// extras (docs/authoring.md). Several meshes are fractured in parallel (batch pre-fracture), each into
// DIR/<mesh stem>/.
//
// Everything is computed before anything is written, and the output is staged in a sibling folder renamed to
// DIR at the end, so that an error leaves no partial output. SIGINT and SIGTERM are held back while the
// staging folder exists; staging folders of killed runs (".DIR.rubble-tmp-PID" of a dead PID) are removed.
// Objects are written under unique names: objects sharing a name (which glTF allows) become "wall",
// "wall_2", ..., and a piece never takes a kept object's name.
// Exit codes: 0 every mesh fractured and written; 1 a fracture or a write failed (the other meshes are
// written); 2 unreadable or invalid mesh (the checks of `rubble check`, self-intersections included), or a
// usage error (nothing written); 3 the impact misses a mesh (no pieces for it; the other meshes are written).
// --json prints
// {"input":{"volume","triangles","closed"},"cut","dropped_volume","pieces":[{"volume","triangles",
// "closed","oriented","center_of_mass":[x,y,z],"convex_parts","concavity"}],"timings_ms":{"cell","boolean",
// "islands","decomposition","total"}} (with "error" added when the fracture failed); "cut" is false when no
// piece has a cut face (the one piece is the input), "dropped_volume" the volume of pieces below the drop
// fraction, "concavity" the parts' partConcavity (a fraction of the piece's diagonal; -1 without parts). With
// several meshes {"results":[...]} with one such object per mesh plus "file". A multi-object input adds
// "object" (the name of the object fractured) and "kept" (objects written unchanged); --depth D > 1 adds
// "levels":[{"level","pieces","volume","dropped_volume","bonds","failed"}] for levels 1..D. Every exit prints
// an object: a usage error or an invalid input (exit 2) {"error"}; a failed write the results plus "error".
#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "JsonText.hpp"
#include "Staging.hpp"
#include "Subcommand.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/PartConcavity.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/io/SceneIO.hpp"
#include "rubble/structure/BondGraph.hpp"
#include "rubble/structure/Material.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;
constexpr int kExitMissed = 3;

// Numbers are kept as typed and checked by rubble::checkParamText, so that the CLI refuses what every API
// refuses with the same message (and --json reports it).
struct FractureArgs {
    std::vector<std::string> files;
    std::string impact;
    std::string normal = "0,1,0";
    std::string impulse = "1";
    std::string cells = "1";
    std::string depth = "1";
    std::string seed = "1";
    std::string interiorTexture;
    std::string backend; // empty: the library's default
    std::string output;
    bool json = false;
    std::string format = "obj";
    std::string material;              // a preset's roughness (docs/roughness.md); empty: flat
    std::optional<double> roughness;   // amplitude, relative to the cell size
    std::optional<double> hurst;       // Hurst exponent
    std::optional<double> featureSize; // longest wavelength, relative to the cell size
};

struct PieceOut {
    std::string name;
    rubble::Mesh mesh;
    rubble::MassProperties mass;
    bool closed = false;
    bool oriented = false;
    std::vector<rubble::ConvexPolytope> parts; // convex parts (for bonds and the next level)
    std::vector<rubble::Mesh> partMeshes;      // the parts as written (read from the file for kept objects)
    int parent = -1;                           // index of the parent chunk in MeshJob::pieces
    int level = 1;                             // 0: an object of the input written unchanged
    double concavity = -1;                     // of the parts (partConcavity); -1: not measured
};

// A bond between two sibling chunks (indices into MeshJob::pieces).
struct BondOut {
    std::size_t a = 0, b = 0;
    double area = 0;
    rubble::Vec3 centroid;
};

struct LevelStats {
    std::size_t pieces = 0;
    double volume = 0;
    double droppedVolume = 0;
    std::size_t bonds = 0;
    std::size_t failed = 0; // chunks of the level above that could not be fractured (kept whole)
};

enum class Outcome { Fractured, Missed, Failed, Invalid };

// Everything one mesh produced; written to disk only after every mesh is done.
struct MeshJob {
    std::string file;
    std::string folder;       // sub-folder of DIR ("" for a single mesh)
    rubble::AssetScene scene; // the input as read (materials, other objects)
    std::size_t target = 0;   // the object fractured
    bool multiObject = false; // the input has several (leaf) objects
    rubble::Mesh input;
    double inputVolume = 0;
    bool inputClosed = false;
    Outcome outcome = Outcome::Fractured;
    std::string message;
    std::vector<PieceOut> pieces; // kept objects (level 0), then level 1, 2, ... (parents before children)
    std::vector<BondOut> bonds;   // between siblings
    std::vector<LevelStats> levels;
    rubble::FractureTimings timings;
    double decompositionMs = 0; // the incremental update
    double parentDecompositionMs = 0;
    double droppedVolume = 0;    // pieces below the drop fraction
    bool cut = false;            // some piece has a cut face (else the one piece is the input itself)
    std::set<std::string> names; // the names given so far, lower case
};

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::optional<rubble::Vec3> parsePoint(const std::string& text) {
    double v[3];
    const char* p = text.data();
    const char* end = text.data() + text.size();
    for (int i = 0; i < 3; ++i) {
        while (p < end && *p == ' ')
            ++p;
        const auto [next, ec] = std::from_chars(p, end, v[i]);
        if (ec != std::errc() || !std::isfinite(v[i]))
            return std::nullopt;
        p = next;
        while (p < end && *p == ' ')
            ++p;
        if (i < 2) {
            if (p == end || *p != ',')
                return std::nullopt;
            ++p;
        }
    }
    if (p != end)
        return std::nullopt;
    return rubble::Vec3{v[0], v[1], v[2]};
}

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string pieceName(const std::string& prefix, std::size_t i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "_%03zu", i);
    return prefix + buf;
}

// A name for an output object that no earlier one of the job has, without regard to case ("wall", "wall_2",
// ...; objects and glTF nodes may share names, files may not), usable as a file name (no '/', '\\' or
// control characters, not "." or "..").
std::string claimName(MeshJob& job, std::string wanted) {
    for (char& c : wanted)
        if (c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20)
            c = '_';
    if (wanted.empty() || wanted == "." || wanted == "..")
        wanted = "object";
    auto lower = [](std::string t) {
        for (char& c : t)
            c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        return t;
    };
    std::string name = wanted;
    for (int n = 2; !job.names.insert(lower(name)).second; ++n)
        name = wanted + "_" + std::to_string(n);
    return name;
}

// The pieces of one fracture with their parts; false when the fracture failed (message set).
struct Fractured {
    std::vector<PieceOut> pieces;
    double droppedVolume = 0;
    rubble::FractureTimings timings;
    double decompositionMs = 0;
    bool cut = false;
};

Fractured piecesOf(rubble::FractureResult& fr, const std::vector<rubble::ConvexPolytope>& parentParts,
                   const std::string& prefix, int parent, int level) {
    Fractured out;
    out.timings = fr.stats.timings;
    out.droppedVolume = fr.droppedVolume;
    for (const rubble::Piece& piece : fr.pieces)
        out.cut = out.cut || std::find(piece.mesh.materials.begin(), piece.mesh.materials.end(),
                                       rubble::kInteriorMaterial) != piece.mesh.materials.end();
    const auto td = Clock::now();
    // Level 1 updates the parent's parts as the runtime does; deeper chunks get fresh decompositions, since
    // incremental parts, clipped again on every level, stand out further and further from small chunks.
    std::vector<std::vector<rubble::ConvexPolytope>> parts;
    if (level <= 1) {
        parts = rubble::updateDecomposition(parentParts, fr);
    } else {
        for (const rubble::Piece& piece : fr.pieces) {
            auto d = rubble::decompose(piece.mesh);
            parts.push_back(d ? d->parts : std::vector<rubble::ConvexPolytope>{});
        }
    }
    out.decompositionMs = msSince(td);
    const std::vector<double> concavity = rubble::pieceConcavity(fr, parts);
    rubble::CheckOptions noSelfIntersections;
    noSelfIntersections.selfIntersections = false;
    for (std::size_t i = 0; i < fr.pieces.size(); ++i) {
        PieceOut p;
        p.name = pieceName(prefix, i);
        const rubble::MeshReport r = rubble::checkMesh(fr.pieces[i].mesh, noSelfIntersections);
        p.closed = r.closed && r.manifold();
        p.oriented = r.oriented && r.outward;
        if (i < parts.size())
            p.parts = std::move(parts[i]);
        for (const rubble::ConvexPolytope& part : p.parts)
            p.partMeshes.push_back(part.toMesh());
        p.mass = fr.pieces[i].mass;
        p.concavity = concavity[i];
        p.mesh = std::move(fr.pieces[i].mesh);
        p.parent = parent;
        p.level = level;
        out.pieces.push_back(std::move(p));
    }
    return out;
}

// The bonds between the given sibling pieces (indices into pieces).
void addBonds(MeshJob& job, const std::vector<std::size_t>& siblings) {
    std::vector<std::vector<rubble::ConvexPolytope>> solids;
    for (std::size_t i : siblings)
        solids.push_back(job.pieces[i].parts);
    for (const rubble::Bond& b : rubble::buildBonds(solids, rubble::BondSettings{}))
        job.bonds.push_back({siblings[b.a], siblings[b.b], b.section.area, b.section.centroid});
}

// True when no other object of the scene has this one as its parent.
bool isLeaf(const rubble::AssetScene& scene, std::size_t i) {
    return std::none_of(scene.objects.begin(), scene.objects.end(),
                        [&](const rubble::AssetObject& o) { return o.parent == static_cast<int>(i); });
}

// The parts of a mesh: its collision parts from the file when it has some, else a fresh decomposition.
std::vector<rubble::ConvexPolytope> partsOf(const rubble::Mesh& mesh,
                                            const std::vector<rubble::Mesh>& given) {
    std::vector<rubble::ConvexPolytope> parts;
    for (const rubble::Mesh& m : given)
        if (auto hull = rubble::convexHull(m.positions))
            parts.push_back(std::move(hull.value()));
    if (!parts.empty() && parts.size() == given.size())
        return parts;
    auto d = rubble::decompose(mesh); // a game computes this once, at load time
    return d ? d->parts : std::vector<rubble::ConvexPolytope>{};
}

// Fractures one validated mesh and updates its decomposition, then the pieces level by level down to depth
// (runs on a worker).
void runJob(MeshJob& job, const rubble::Impact& impact, const rubble::FractureParams& params,
            std::uint64_t seed, int depth, int cells) {
    // Objects of a multi-object input other than the one fractured are written unchanged (level 0).
    std::vector<std::size_t> roots;
    if (job.multiObject)
        for (std::size_t i = 0; i < job.scene.objects.size(); ++i) {
            const rubble::AssetObject& o = job.scene.objects[i];
            if (i == job.target || !isLeaf(job.scene, i))
                continue;
            PieceOut p;
            p.name = claimName(job, o.name);
            p.mesh = o.mesh;
            p.mass = rubble::computeMassProperties(o.mesh);
            rubble::CheckOptions quick;
            quick.selfIntersections = false;
            const rubble::MeshReport r = rubble::checkMesh(o.mesh, quick);
            p.closed = r.closed && r.manifold();
            p.oriented = r.oriented && r.outward;
            p.partMeshes = o.collision;
            p.parts = partsOf(o.mesh, o.collision);
            p.level = 0;
            roots.push_back(job.pieces.size());
            job.pieces.push_back(std::move(p));
        }
    const auto tp = Clock::now();
    const std::vector<rubble::ConvexPolytope> parent =
        partsOf(job.input, job.scene.objects[job.target].collision);
    job.parentDecompositionMs = msSince(tp);
    auto fr = rubble::fracture(job.input, impact, params, seed);
    if (!fr) {
        job.outcome = fr.error().code == rubble::ErrorCode::NoIntersection ? Outcome::Missed
                      : fr.error().code == rubble::ErrorCode::InvalidInput ? Outcome::Invalid
                                                                           : Outcome::Failed;
        job.message = fr.error().message;
        return;
    }
    const std::string prefix = job.multiObject ? job.scene.objects[job.target].name : "piece";
    Fractured first = piecesOf(*fr, parent, prefix, -1, 1);
    job.timings = first.timings;
    job.droppedVolume = first.droppedVolume;
    job.decompositionMs = first.decompositionMs;
    job.cut = first.cut;
    std::vector<std::size_t> level;
    for (PieceOut& p : first.pieces) {
        p.name = claimName(job, p.name);
        level.push_back(job.pieces.size());
        roots.push_back(job.pieces.size());
        job.pieces.push_back(std::move(p));
    }
    if (depth <= 1)
        return;
    LevelStats stats;
    stats.pieces = level.size();
    stats.droppedVolume = first.droppedVolume;
    for (std::size_t i : level)
        stats.volume += job.pieces[i].mass.volume;
    const std::size_t before = job.bonds.size();
    addBonds(job, roots);
    stats.bonds = job.bonds.size() - before;
    job.levels.push_back(stats);

    // Deeper levels: every chunk shattered into `cells` cells around its centre of mass, the cells' domain
    // as large as the chunk's bounding-box diagonal.
    for (int l = 2; l <= depth; ++l) {
        LevelStats ls;
        std::vector<std::size_t> next;
        for (std::size_t i : level) {
            const rubble::Mesh chunk = job.pieces[i].mesh;
            const double diagonal = length(chunk.bounds().hi - chunk.bounds().lo);
            rubble::FractureParams deeper = params;
            deeper.pattern = rubble::CellPattern::Shatter;
            deeper.cells = std::max(2, cells);
            deeper.sizeLaw.minSize = deeper.sizeLaw.maxSize = diagonal;
            rubble::Impact centre;
            centre.point = job.pieces[i].mass.centerOfMass;
            const std::uint64_t chunkSeed =
                seed * 0x9E3779B97F4A7C15ull + i * 1315423911ull + std::uint64_t(l);
            auto sub = rubble::fracture(chunk, centre, deeper, chunkSeed);
            if (!sub || sub->pieces.size() < 2) {
                ++ls.failed; // kept whole: it stands for itself on this level
                ls.volume += job.pieces[i].mass.volume;
                next.push_back(i);
                continue;
            }
            Fractured f = piecesOf(*sub, job.pieces[i].parts, job.pieces[i].name, static_cast<int>(i), l);
            ls.droppedVolume += f.droppedVolume;
            std::vector<std::size_t> siblings;
            for (PieceOut& p : f.pieces) {
                p.name = claimName(job, p.name);
                ls.volume += p.mass.volume;
                siblings.push_back(job.pieces.size());
                next.push_back(job.pieces.size());
                job.pieces.push_back(std::move(p));
            }
            const std::size_t had = job.bonds.size();
            addBonds(job, siblings);
            ls.bonds += job.bonds.size() - had;
        }
        ls.pieces = next.size();
        ls.droppedVolume += job.levels.back().droppedVolume; // dropped on this level and above
        job.levels.push_back(ls);
        level = std::move(next);
    }
}

nlohmann::json jsonOf(const MeshJob& job, bool withFile) {
    nlohmann::json j;
    if (withFile)
        j["file"] = rubble::tools::utf8Escaped(job.file);
    j["input"] = {
        {"volume", job.inputVolume}, {"triangles", job.input.triangleCount()}, {"closed", job.inputClosed}};
    j["cut"] = job.cut;
    j["dropped_volume"] = job.droppedVolume;
    j["pieces"] = nlohmann::json::array();
    for (const PieceOut& p : job.pieces) {
        if (p.level != 1)
            continue;
        const rubble::Vec3& c = p.mass.centerOfMass;
        j["pieces"].push_back({{"volume", p.mass.volume},
                               {"triangles", p.mesh.triangleCount()},
                               {"closed", p.closed},
                               {"oriented", p.oriented},
                               {"center_of_mass", {c.x, c.y, c.z}},
                               {"convex_parts", p.partMeshes.size()},
                               {"concavity", p.concavity}});
    }
    if (job.multiObject) {
        j["object"] = rubble::tools::utf8Escaped(job.scene.objects[job.target].name);
        j["kept"] = std::count_if(job.pieces.begin(), job.pieces.end(),
                                  [](const PieceOut& p) { return p.level == 0; });
    }
    if (!job.levels.empty()) {
        j["levels"] = nlohmann::json::array();
        for (std::size_t l = 0; l < job.levels.size(); ++l) {
            const LevelStats& s = job.levels[l];
            j["levels"].push_back({{"level", l + 1},
                                   {"pieces", s.pieces},
                                   {"volume", s.volume},
                                   {"dropped_volume", s.droppedVolume},
                                   {"bonds", s.bonds},
                                   {"failed", s.failed}});
        }
    }
    j["timings_ms"] = {{"cell", job.timings.cellMs},
                       {"boolean", job.timings.booleanMs},
                       {"islands", job.timings.islandsMs},
                       {"decomposition", job.decompositionMs},
                       {"total", job.timings.totalMs + job.decompositionMs}};
    if (job.outcome == Outcome::Failed)
        j["error"] = rubble::tools::utf8Escaped(job.message);
    return j;
}

void printSummary(std::ostream& out, const MeshJob& job, const fs::path& dir) {
    if (job.outcome == Outcome::Missed) {
        out << job.file << ": the impact misses the mesh: no pieces (" << job.message << ")\n";
        return;
    }
    if (job.outcome == Outcome::Failed) {
        out << job.file << ": fracture failed: " << job.message << "\n";
        return;
    }
    double sum = 0;
    std::size_t count = 0;
    for (const PieceOut& p : job.pieces)
        if (p.level == 1) {
            sum += p.mass.volume;
            ++count;
        }
    out << job.file << ": " << count << (count == 1 ? " piece" : " pieces");
    if (job.multiObject)
        out << " of object '" << job.scene.objects[job.target].name << "'";
    out << " written to " << dir.string() << "\n";
    char line[160];
    std::snprintf(line, sizeof line, "  %-10s %9s %12s %6s %7s %9s  %s\n", "piece", "triangles", "volume",
                  "parts", "closed", "oriented", "centre of mass");
    out << line;
    for (std::size_t i = 0; i < job.pieces.size(); ++i) {
        const PieceOut& p = job.pieces[i];
        if (p.level != 1)
            continue;
        const rubble::Vec3& c = p.mass.centerOfMass;
        std::snprintf(line, sizeof line, "  %-10s %9zu %12s %6zu %7s %9s  (%s, %s, %s)\n", p.name.c_str(),
                      p.mesh.triangleCount(), num(p.mass.volume).c_str(), p.partMeshes.size(),
                      p.closed ? "yes" : "NO", p.oriented ? "yes" : "NO", num(c.x).c_str(), num(c.y).c_str(),
                      num(c.z).c_str());
        out << line;
    }
    out << "  volume: input " << num(job.inputVolume) << ", pieces " << num(sum);
    if (job.droppedVolume > 0)
        out << ", dropped " << num(job.droppedVolume) << " (pieces below the drop fraction)";
    out << " (relative difference "
        << num(std::abs(sum + job.droppedVolume - job.inputVolume) / job.inputVolume) << ")\n";
    for (std::size_t l = 0; l < job.levels.size(); ++l) {
        const LevelStats& s = job.levels[l];
        out << "  level " << l + 1 << ": " << s.pieces << " chunks, volume " << num(s.volume) << " + dropped "
            << num(s.droppedVolume) << ", " << s.bonds << " bonds between siblings";
        if (s.failed > 0)
            out << ", " << s.failed << " chunks kept whole";
        out << "\n";
    }
    if (job.multiObject)
        out << "  " << std::count_if(job.pieces.begin(), job.pieces.end(), [](const PieceOut& p) {
            return p.level == 0;
        }) << " other objects written unchanged\n";
    if (!job.cut)
        out << "  nothing was cut: the piece is the whole input (the impact's cells contain the whole mesh, "
               "or "
               "everything they cut off was below the drop fraction)\n";
    out << "  time: cells " << num(job.timings.cellMs) << " ms, booleans " << num(job.timings.booleanMs)
        << " ms, islands " << num(job.timings.islandsMs) << " ms, decomposition update "
        << num(job.decompositionMs) << " ms, total " << num(job.timings.totalMs + job.decompositionMs)
        << " ms (parent decomposition, "
        << "done once at load time: " << num(job.parentDecompositionMs) << " ms)\n";
}

nlohmann::json vec3(const rubble::Vec3& v) {
    return {v.x, v.y, v.z};
}

// The node extras of a piece: mass properties (density 1), level and parent.
std::string extrasOf(const MeshJob& job, std::size_t i) {
    const PieceOut& p = job.pieces[i];
    return rubble::pieceExtras(p.mass, p.level,
                               p.parent >= 0 ? job.pieces[static_cast<std::size_t>(p.parent)].name : "");
}

nlohmann::json bondsOf(const MeshJob& job, int parent) {
    nlohmann::json bonds = nlohmann::json::array();
    for (const BondOut& b : job.bonds)
        if (job.pieces[b.a].parent == parent)
            bonds.push_back({{"a", job.pieces[b.a].name},
                             {"b", job.pieces[b.b].name},
                             {"area", b.area},
                             {"centroid", vec3(b.centroid)}});
    return bonds;
}

rubble::Status writeJob(const MeshJob& job, const fs::path& dir, const std::string& format,
                        const std::vector<rubble::AssetMaterial>& materials) {
    if (format == "gltf") {
        std::vector<rubble::GltfNode> nodes;
        for (std::size_t i = 0; i < job.pieces.size(); ++i) {
            const PieceOut& p = job.pieces[i];
            rubble::GltfNode node{p.name,       p.mesh,           p.mass.centerOfMass,
                                  p.partMeshes, extrasOf(job, i), p.parent};
            if (nlohmann::json bonds = bondsOf(job, static_cast<int>(i)); !bonds.empty()) {
                nlohmann::json extras = nlohmann::json::parse(node.extras);
                extras["rubble"]["bonds"] = bonds;
                node.extras = extras.dump();
            }
            nodes.push_back(std::move(node));
        }
        std::string sceneExtras;
        if (!job.levels.empty())
            sceneExtras = nlohmann::json{{"rubble", {{"bonds", bondsOf(job, -1)}}}}.dump();
        return rubble::writeGltf(dir / "pieces.gltf", nodes, materials, sceneExtras);
    }
    for (const PieceOut& p : job.pieces) {
        rubble::ObjWriteOptions options;
        options.objectName = p.name;
        options.collision = p.partMeshes;
        options.materials = materials;
        if (rubble::Status s = rubble::writeObj(dir / (p.name + ".obj"), p.mesh, options); !s)
            return s;
    }
    return {};
}

// Draws "fracturing [=====     ] 2/5" on stderr (only called when stderr is a terminal).
void drawProgress(std::size_t done, std::size_t total) {
    const std::size_t width = 30;
    const std::size_t filled = total ? done * width / total : width;
    std::fprintf(stderr, "\rfracturing [%s%s] %zu/%zu", std::string(filled, '=').c_str(),
                 std::string(width - filled, ' ').c_str(), done, total);
    if (done == total)
        std::fprintf(stderr, "\n");
    std::fflush(stderr);
}

// Writes the fractured meshes into a staging folder next to DIR and renames it to DIR.
int commitOutput(const std::vector<MeshJob>& jobs, const fs::path& dir, const std::string& format, bool batch,
                 const std::optional<rubble::AssetMaterial>& interior, std::string& error) {
    std::error_code ec;
    const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
    fs::create_directories(parent, ec);
    rubble::tools::removeStaleStaging(parent); // left by earlier runs that were killed
    // SIGINT / SIGTERM wait until the staging folder is renamed or removed.
    const rubble::tools::DeferSignals deferred;
    const fs::path stage = rubble::tools::stagingPath(dir);
    fs::remove_all(stage, ec);
    auto fail = [&](const std::string& message) {
        std::cerr << "rubble fracture: " << message << "\n";
        error = message;
        fs::remove_all(stage, ec);
        return kExitFailed;
    };
    if (!fs::create_directory(stage, ec))
        return fail("cannot create " + stage.string() + ": " + ec.message());
    for (const MeshJob& job : jobs) {
        if (job.outcome != Outcome::Fractured)
            continue;
        const fs::path sub = batch ? stage / job.folder : stage;
        if (batch && !fs::create_directory(sub, ec))
            return fail("cannot create " + sub.string() + ": " + ec.message());
        std::vector<rubble::AssetMaterial> materials = job.scene.materials;
        if (interior) {
            materials.erase(std::remove_if(materials.begin(), materials.end(),
                                           [&](const auto& m) { return m.name == interior->name; }),
                            materials.end());
            materials.push_back(*interior);
        }
        if (rubble::Status s = writeJob(job, sub, format, materials); !s)
            return fail(s.message());
    }
    if (fs::exists(dir, ec))
        fs::remove(dir, ec); // empty (checked before fracturing)
    fs::rename(stage, dir, ec);
    if (ec)
        return fail("cannot rename " + stage.string() + " to " + dir.string() + ": " + ec.message());
    return kExitOk;
}

// Prints {"error": message} on stdout (--json: every exit prints a result object).
void printJsonError(const std::string& message) {
    std::cout << rubble::tools::dumpJson(nlohmann::json{{"error", rubble::tools::utf8Escaped(message)}})
              << "\n";
}

int runFracture(const FractureArgs& args) {
    auto usage = [&](const std::string& message) {
        std::cerr << "rubble fracture: " << message << "\n";
        if (args.json)
            printJsonError(message);
        return kExitUsage;
    };
    for (auto [option, name, text] : {std::tuple{"--impact", "point", &args.impact},
                                      {"--normal", "normal", &args.normal},
                                      {"--impulse", "impulse", &args.impulse},
                                      {"--cells", "cells", &args.cells},
                                      {"--depth", "depth", &args.depth},
                                      {"--seed", "seed", &args.seed}})
        if (rubble::Status s = rubble::checkParamText(name, *text); !s)
            return usage(std::string(option) + ": " + s.message());
    const int cells = std::stoi(args.cells);
    const int depth = std::stoi(args.depth);
    if (rubble::Status s = rubble::checkPieceBudget(cells, depth); !s)
        return usage("--cells and --depth: " + s.message());
    const std::uint64_t seed = std::stoull(args.seed);
    const auto point = parsePoint(args.impact);
    const auto normal = parsePoint(args.normal);
    if (!point || !normal)
        return usage("--impact or --normal is not three numbers X,Y,Z in decimal");
    fs::path dir = fs::path(args.output).lexically_normal();
    if (!dir.has_filename() && dir.has_parent_path()) // "out/" names the folder "out"
        dir = dir.parent_path();
    if (dir.empty() || dir.filename() == "." || dir.filename() == "..")
        return usage("-o '" + args.output + "' does not name a folder to create");
    if (depth > 1 && args.format != "gltf")
        return usage("--depth " + std::to_string(depth) +
                     " writes a node tree: it needs --format gltf (OBJ has no hierarchy)");
    std::optional<rubble::AssetMaterial> interior;
    if (!args.interiorTexture.empty()) {
        std::error_code exists;
        if (!fs::is_regular_file(args.interiorTexture, exists))
            return usage("--interior-texture '" + args.interiorTexture + "' is not a readable file");
        interior.emplace();
        interior->name = std::string(rubble::kInteriorMaterialName);
        interior->baseColor = {1, 1, 1};
        interior->maps.push_back({"map_Kd", "", fs::path(args.interiorTexture), "", ""});
    }
    std::error_code ec;
    if (fs::exists(dir, ec) && (!fs::is_directory(dir, ec) || !fs::is_empty(dir, ec)))
        return usage("the output folder '" + args.output +
                     "' exists and is not an empty folder (choose another one or remove it)");

    rubble::FractureParams params;
    if (cells > 1) {
        params.pattern = rubble::CellPattern::Shatter;
        params.cells = cells;
    }
    auto roughness = rubble::chooseRoughness({args.material, args.roughness, args.hurst, args.featureSize});
    if (!roughness)
        return usage(roughness.error().message);
    params.roughness = *roughness;
    if (args.backend == "corefine")
        params.backend = rubble::BooleanKind::Corefine;
    else if (args.backend == "nef")
        params.backend = rubble::BooleanKind::Nef;
    else if (args.backend == "fast")
        params.backend = rubble::BooleanKind::Fast;
    rubble::Impact impact;
    impact.point = *point;
    impact.normal = *normal;
    impact.impulse = std::strtod(args.impulse.c_str(), nullptr);

    // Read and validate every input first: a bad one stops everything before anything is computed or written.
    const bool batch = args.files.size() > 1;
    std::vector<MeshJob> jobs(args.files.size());
    std::set<std::string> folders;
    for (std::size_t i = 0; i < args.files.size(); ++i) {
        MeshJob& job = jobs[i];
        job.file = args.files[i];
        job.folder = fs::path(job.file).stem().string();
        if (batch && !folders.insert(job.folder).second)
            return usage("two inputs would be written to the same folder '" + job.folder + "' (" + job.file +
                         ")");
        auto scene = rubble::readScene(job.file);
        if (!scene)
            return usage(scene.error().message);
        job.scene = std::move(scene.value());
        for (const std::string& w : job.scene.warnings)
            std::cerr << "rubble fracture: warning: " << w << "\n";
        // Several leaf objects: the one containing the impact, else the one nearest to it.
        std::vector<std::size_t> leaves;
        for (std::size_t o = 0; o < job.scene.objects.size(); ++o)
            if (isLeaf(job.scene, o))
                leaves.push_back(o);
        job.multiObject = leaves.size() > 1;
        job.target = leaves.front();
        if (job.multiObject) {
            double best = std::numeric_limits<double>::infinity();
            for (std::size_t o : leaves) {
                const rubble::Mesh& m = job.scene.objects[o].mesh;
                const double d =
                    rubble::windingNumber(m, *point) > 0.5 ? 0.0 : rubble::distanceToSurface(m, *point);
                if (d < best) {
                    best = d;
                    job.target = o;
                }
            }
        }
        const rubble::Mesh& mesh = job.scene.objects[job.target].mesh;
        const std::string what =
            job.multiObject ? job.file + " (object '" + job.scene.objects[job.target].name + "')" : job.file;
        // The checks of `rubble check`, self-intersections included (a load-time cost, as in a game's
        // loader).
        const rubble::MeshReport r = rubble::checkMesh(mesh);
        if (!r.valid())
            return usage(what + ": not a valid solid, cannot fracture it: " +
                         (r.problems.empty() ? std::string("invalid mesh") : r.problems.front()) +
                         " (see rubble check " + job.file + ")");
        job.inputClosed = r.closed;
        job.inputVolume = rubble::signedVolume(mesh);
        job.input = mesh;
    }

    // Fracture: inline for one mesh, on a thread pool for several.
    if (!batch) {
        runJob(jobs[0], impact, params, seed, depth, cells);
    } else {
        const int workers = static_cast<int>(
            std::min<std::size_t>(jobs.size(), std::max(1u, std::thread::hardware_concurrency())));
        const bool progress = ::isatty(STDERR_FILENO) == 1;
        std::mutex mutex;
        std::size_t done = 0;
        rubble::ThreadPool pool(workers);
        if (progress)
            drawProgress(0, jobs.size());
        for (MeshJob& job : jobs)
            pool.submit([&, j = &job] {
                runJob(*j, impact, params, seed, depth, cells);
                std::lock_guard lock(mutex);
                ++done;
                if (progress)
                    drawProgress(done, jobs.size());
            });
        pool.waitIdle();
    }

    int code = kExitOk;
    bool anyFractured = false;
    for (const MeshJob& job : jobs) {
        if (job.outcome == Outcome::Invalid)
            return usage(job.file + ": " + job.message);
        if (job.outcome == Outcome::Failed)
            code = kExitFailed;
        else if (job.outcome == Outcome::Missed && code == kExitOk)
            code = kExitMissed;
        anyFractured |= job.outcome == Outcome::Fractured;
    }
    auto jsonDoc = [&] {
        if (!batch)
            return jsonOf(jobs[0], false);
        nlohmann::json doc;
        doc["results"] = nlohmann::json::array();
        for (const MeshJob& job : jobs)
            doc["results"].push_back(jsonOf(job, true));
        return doc;
    };
    std::string writeError;
    if (anyFractured)
        if (const int written = commitOutput(jobs, dir, args.format, batch, interior, writeError);
            written != kExitOk) {
            if (args.json) {
                nlohmann::json doc = jsonDoc();
                doc["error"] = rubble::tools::utf8Escaped(writeError);
                std::cout << rubble::tools::dumpJson(doc) << "\n";
            }
            return written;
        }

    std::ostream& text = args.json ? std::cerr : std::cout;
    for (const MeshJob& job : jobs)
        if (!args.json || job.outcome != Outcome::Fractured)
            printSummary(text, job, batch ? dir / job.folder : dir);
        else if (!job.cut)
            text << job.file << ": nothing was cut: the piece is the whole input\n";
    if (args.json)
        std::cout << rubble::tools::dumpJson(jsonDoc()) << "\n";
    return code;
}

const rubble::tools::Registrar registrar{
    {"fracture", "Fracture meshes at an impact point; write the pieces (OBJ or glTF) with their convex parts",
     [](CLI::App& app) {
         auto args = std::make_shared<FractureArgs>();
         app.footer(
             "The impact point is in each mesh's own coordinates. Pieces are written as DIR/piece_000.obj "
             "... "
             "(cut faces in the material 'interior' of the .mtl, convex parts as objects UCX_piece_000_NN "
             "for "
             "Unreal) or DIR/pieces.gltf (--format gltf: one node per piece at its centre of mass with mass "
             "properties in extras, convex parts as child nodes named '-convcolonly' for Godot). Source "
             "materials and textures are kept (images copied to DIR/textures/). A file with several objects "
             "(e.g. a pieces.gltf written before) has the object containing, or nearest to, the impact "
             "fractured and the others written unchanged. With several meshes each goes to DIR/<mesh stem>/, "
             "fractured in parallel. DIR must not exist or be empty; nothing is written unless the inputs "
             "are "
             "valid.\n"
             "Exit codes: 0 every mesh fractured and written; 1 a fracture or a write failed (the other "
             "meshes "
             "are written); 2 unreadable or invalid mesh, or a usage error (nothing written); 3 the impact "
             "misses a mesh: no pieces for it (the other meshes are written).\n"
             "--json timings_ms: cell, boolean, islands as in the fracture kernel; decomposition is the "
             "incremental update of the parent's convex parts (the parent's own decomposition is a load-time "
             "cost and not counted); total = fracture + decomposition.");
         app.add_option("meshes", args->files,
                        "closed mesh files (.obj, .off, .stl, .ply, .3ds, .gltf, .glb)")
             ->required();
         app.add_option("--impact", args->impact, "impact point X,Y,Z in the mesh's coordinates")->required();
         const rubble::CellSizeLaw law;
         app.add_option("--normal", args->normal,
                        "surface normal at the impact X,Y,Z (out of the mesh; not all 0)")
             ->capture_default_str();
         app.add_option(
                "--impulse", args->impulse,
                "impact impulse (N s), " + rubble::describeParamRange(*rubble::findParamRange("impulse")) +
                    "; the cut region's edge is " + num(law.base) + " + " + num(law.scale) + " impulse^" +
                    num(law.exponent) + ", clamped to [" + num(law.minSize) + ", " + num(law.maxSize) + "]")
             ->capture_default_str();
         app.add_option("--cells", args->cells,
                        "1: the thesis's single Voronoi cell; K > 1: shatter into K cells (1.." +
                            std::to_string(rubble::kMaxShatterCells) + ")")
             ->capture_default_str();
         app.add_option(
                "--depth", args->depth,
                "levels of pre-fracture: D > 1 shatters every piece again into --cells cells (at least "
                "2), D-1 times, into a glTF node tree with bonds between sibling chunks (--format gltf); "
                "1.." +
                    std::to_string(rubble::kMaxFractureDepth) + ", with at most " +
                    num(static_cast<double>(rubble::kMaxTotalPieces)) + " pieces in all")
             ->capture_default_str();
         app.add_option("--interior-texture", args->interiorTexture,
                        "image for the material 'interior' of the cut faces (copied to DIR/textures/)");
         app.add_option("--seed", args->seed,
                        "random seed 0..18446744073709551615 (same seed, same pieces, byte for byte)")
             ->capture_default_str();
         app.add_option("--material", args->material,
                        "cut with this material's rough cut faces (" + rubble::materialNames() +
                            "; docs/roughness.md); without it, and with --roughness 0, cuts are flat");
         app.add_option("--roughness", args->roughness,
                        "amplitude of rough cut faces, a fraction of the cell size (0: flat)");
         app.add_option("--hurst", args->hurst, "Hurst exponent of rough cut faces, in (0, 1]");
         app.add_option(
             "--feature-size", args->featureSize,
             "longest wavelength of rough cut faces, a fraction of the cell size (0: 8 amplitudes)");
         app.add_option("--backend", args->backend, "boolean backend (default: the library's default)")
             ->check(CLI::IsMember({"corefine", "nef", "fast"}));
         app.add_option("-o,--output", args->output, "output folder (must not exist, or be empty)")
             ->required();
         app.add_flag("--json", args->json, "print the results as JSON on stdout (messages go to stderr)");
         app.add_option("--format", args->format, "output format of the pieces")
             ->check(CLI::IsMember({"obj", "gltf"}))
             ->capture_default_str();
         return [args] { return runFracture(*args); };
     }}};

} // namespace
