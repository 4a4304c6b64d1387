// `rubble check MESH... [--json] [--repair -o OUT] [--no-self-intersections]`
//
// Exit codes: 0 all meshes valid (after repair, with --repair); 1 some mesh readable but invalid;
// 2 some mesh unreadable, or a usage error. In --json mode stdout holds only the JSON document
// {"meshes":[{"file","valid","problems":[...],"vertices","triangles","closed","manifold","oriented",
// "self_intersections","volume","center_of_mass":[x,y,z],"bbox":[[lo],[hi]]}]}, where self_intersections is
// the number of intersecting triangle pairs or null when the test did not run; an unreadable file appears as
// {"file","error"}. With --repair the entries describe the repaired meshes, "file" being the path written (or
// {"file","error"} when it could not be written; exit 2). A mesh still invalid after repair is not written:
// its entry keeps the input's "file", describes the repaired mesh and adds "written": false (exit 1). Two
// inputs with the same stem are refused with --repair into a folder. Outputs are written through a staging
// file and renamed. Problems and repair notes go to stderr in --json mode. A file with several objects (a
// glTF node tree, an OBJ with several `o`) or with collision parts (glTF
// "-convcolonly" children, OBJ UCX_ objects) is checked object by object: each entry then has "object" (its
// name) and "collision_parts", and a collision part that is not a closed convex solid is a problem of its
// object. --repair takes single-object files only.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "JsonText.hpp"
#include "Staging.hpp"
#include "Subcommand.hpp"
#include "rubble/collision/CollisionTolerance.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/io/SceneIO.hpp"

namespace {

struct CheckArgs {
    std::vector<std::string> files;
    bool json = false;
    bool repair = false;
    bool noSelfIntersections = false;
    std::string output;
};

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string vec(const rubble::Vec3& v) {
    return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")";
}

std::string selfIntersectionText(const rubble::MeshReport& r) {
    if (!r.selfIntersectionsChecked)
        return "not checked (" + r.selfIntersectionNote + ")";
    if (r.selfIntersections == 0)
        return "none";
    return std::string(r.selfIntersectionsCapped ? "at least " : "") + std::to_string(r.selfIntersections) +
           (r.selfIntersections == 1 ? " intersecting triangle pair" : " intersecting triangle pairs");
}

void printStats(std::ostream& out, const rubble::MeshReport& r) {
    auto yesNo = [](bool b) { return b ? "yes" : "no"; };
    out << "  vertices            " << r.vertices << "\n";
    out << "  triangles           " << r.triangles << "\n";
    out << "  closed              " << yesNo(r.closed);
    if (r.boundaryEdges > 0)
        out << " (" << r.boundaryEdges << " open " << (r.boundaryEdges == 1 ? "edge" : "edges") << ")";
    out << "\n  manifold            " << yesNo(r.manifold());
    if (r.nonManifoldEdges > 0)
        out << " (" << r.nonManifoldEdges << " non-manifold " << (r.nonManifoldEdges == 1 ? "edge" : "edges")
            << ")";
    else if (r.nonManifoldVertices > 0)
        out << " (" << r.nonManifoldVertices << " non-manifold "
            << (r.nonManifoldVertices == 1 ? "vertex" : "vertices") << ")";
    out << "\n  oriented            " << yesNo(r.oriented);
    if (r.oriented && r.closed && r.volume != 0 && std::isfinite(r.volume))
        out << (r.volume > 0 ? " (outward)" : " (inside out)");
    out << "\n  self-intersections  " << selfIntersectionText(r) << "\n";
    out << "  volume              " << num(r.volume) << "\n";
    out << "  centre of mass      " << vec(r.centerOfMass) << "\n";
    if (r.bounds.empty())
        out << "  bounding box        empty\n";
    else
        out << "  bounding box        " << vec(r.bounds.lo) << " to " << vec(r.bounds.hi) << "\n";
}

void printProblems(std::ostream& out, const std::vector<std::string>& problems, const char* title) {
    if (problems.empty())
        return;
    out << "  " << title << ":\n";
    for (const std::string& p : problems)
        out << "    - " << p << "\n";
}

nlohmann::json jsonOf(const std::string& file, const rubble::MeshReport& r) {
    nlohmann::json j;
    j["file"] = rubble::tools::utf8Escaped(file);
    j["valid"] = r.valid();
    j["problems"] = nlohmann::json::array();
    for (const std::string& p : r.problems)
        j["problems"].push_back(rubble::tools::utf8Escaped(p));
    j["vertices"] = r.vertices;
    j["triangles"] = r.triangles;
    j["closed"] = r.closed;
    j["manifold"] = r.manifold();
    j["oriented"] = r.oriented;
    if (r.selfIntersectionsChecked)
        j["self_intersections"] = r.selfIntersections;
    else
        j["self_intersections"] = nullptr;
    j["volume"] = r.volume;
    j["center_of_mass"] = {r.centerOfMass.x, r.centerOfMass.y, r.centerOfMass.z};
    if (r.bounds.empty())
        j["bbox"] = {{0, 0, 0}, {0, 0, 0}};
    else
        j["bbox"] = {{r.bounds.lo.x, r.bounds.lo.y, r.bounds.lo.z},
                     {r.bounds.hi.x, r.bounds.hi.y, r.bounds.hi.z}};
    return j;
}

// Problems of a collision part: open, or not convex (its volume below that of its vertices' convex hull by
// more than float storage explains).
std::vector<std::string> partProblems(const rubble::Mesh& part, std::size_t k) {
    std::vector<std::string> problems;
    rubble::CheckOptions quick;
    quick.selfIntersections = false;
    const rubble::MeshReport r = rubble::checkMesh(part, quick);
    const std::string name = "collision part " + std::to_string(k);
    if (!r.closed || !r.manifold() || !r.oriented || !(r.volume > 0)) {
        problems.push_back(name + " is not a closed, outward solid");
        return problems;
    }
    auto hull = rubble::convexHull(part.positions);
    const double hullVolume = hull ? hull->volume() : 0;
    // Float storage moves every face by up to ~1e-7 of the coordinates' magnitude.
    double area = 0, magnitude = 1;
    for (std::size_t t = 0; t < part.triangleCount(); ++t)
        area += length(part.triangleNormal(t)) / 2;
    for (const rubble::Vec3& p : part.positions)
        magnitude = std::max({magnitude, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    if (!(hullVolume - r.volume <= 1e-5 * hullVolume + 1e-6 * magnitude * area))
        problems.push_back(name + " is not convex (volume " + num(r.volume) + ", its convex hull's " +
                           num(hullVolume) + ")");
    return problems;
}

// How far the collision parts reach outside the convex hull of their object (0 when inside).
double outsideHull(const rubble::Mesh& object, const std::vector<rubble::Mesh>& parts) {
    auto hull = rubble::convexHull(object.positions);
    if (!hull)
        return std::numeric_limits<double>::infinity();
    double worst = 0;
    for (const rubble::Mesh& part : parts)
        for (const rubble::Vec3& p : part.positions)
            for (const rubble::PolytopeFaceView& f : hull->faces())
                worst = std::max(worst, f.plane.signedDistance(p));
    return worst;
}

std::string quoteArg(const std::string& s) {
    if (s.find_first_of(" \t'\"$\\") == std::string::npos)
        return s;
    std::string q = "'";
    for (char c : s)
        q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

int runCheck(const CheckArgs& args) {
    namespace fs = std::filesystem;
    if (args.repair && args.output.empty()) {
        std::cerr << "rubble check: --repair needs -o OUT (the file to write the repaired mesh to)\n";
        return 2;
    }
    if (!args.repair && !args.output.empty()) {
        std::cerr << "rubble check: -o is only used with --repair\n";
        return 2;
    }
    std::error_code ec;
    const bool outIsDir =
        !args.output.empty() && (args.files.size() > 1 || fs::is_directory(args.output, ec));
    if (args.repair && !outIsDir && fs::path(args.output).extension() != ".obj") {
        std::cerr << "rubble check: cannot write '" << args.output << "': only .obj output is supported\n";
        return 2;
    }
    // Every input's output path, known before anything is read: two inputs must not share one.
    std::vector<fs::path> outputs;
    if (args.repair) {
        std::set<fs::path> seen;
        for (const std::string& file : args.files) {
            outputs.push_back(outIsDir ? fs::path(args.output) / (fs::path(file).stem().string() + ".obj")
                                       : fs::path(args.output));
            if (!seen.insert(outputs.back()).second) {
                std::cerr << "rubble check: two inputs would be repaired into the same file '"
                          << outputs.back().string() << "' (" << file << "); repair them one at a time\n";
                return 2;
            }
        }
        if (outIsDir)
            fs::create_directories(args.output, ec);
        // Staging files of earlier runs that were killed.
        rubble::tools::removeStaleStaging(outputs.front().parent_path());
    }

    rubble::CheckOptions checkOptions;
    checkOptions.selfIntersections = !args.noSelfIntersections;
    nlohmann::json doc;
    doc["meshes"] = nlohmann::json::array();
    std::ostream& text = args.json ? std::cerr : std::cout;
    int exitCode = 0;
    for (std::size_t i = 0; i < args.files.size(); ++i) {
        const std::string& file = args.files[i];
        if (i > 0 && !args.json)
            std::cout << "\n";
        auto scene = rubble::readScene(file);
        if (!scene) {
            std::cerr << "rubble check: " << scene.error().message << "\n";
            if (args.json)
                doc["meshes"].push_back({{"file", rubble::tools::utf8Escaped(file)},
                                         {"error", rubble::tools::utf8Escaped(scene.error().message)}});
            exitCode = 2;
            continue;
        }
        for (const std::string& w : scene.value().warnings) // e.g. a missing or malformed .mtl
            std::cerr << "rubble check: warning: " << w << "\n";
        const auto& objects = scene.value().objects;
        if (objects.size() > 1 || !objects.front().collision.empty()) {
            if (args.repair) {
                std::cerr << "rubble check: " << file << " has " << objects.size()
                          << " objects or collision parts; --repair takes single-object files\n";
                exitCode = 2;
                continue;
            }
            bool first = true;
            for (const rubble::AssetObject& object : objects) {
                rubble::MeshReport r = rubble::checkMesh(object.mesh, checkOptions);
                for (std::size_t k = 0; k < object.collision.size(); ++k)
                    for (std::string& p : partProblems(object.collision[k], k))
                        r.problems.push_back(std::move(p));
                // Parts may stand out of the hull by the tolerance the decomposition keeps.
                const double outside =
                    object.collision.empty() ? 0 : outsideHull(object.mesh, object.collision);
                const double diagonal = length(r.bounds.hi - r.bounds.lo);
                const double allowed = rubble::partHullTolerance(diagonal);
                if (!(outside <= allowed))
                    r.problems.push_back("collision parts reach " + num(outside) +
                                         " outside the object's convex hull (allowed: " + num(allowed) + ")");
                const bool valid = r.valid() && r.problems.empty();
                const std::string label = file + " (object '" + object.name + "')";
                if (!args.json) {
                    if (!first)
                        std::cout << "\n";
                    std::cout << label << ": " << (valid ? "valid" : "INVALID") << "\n";
                    printStats(std::cout, r);
                    std::cout << "  collision parts     " << object.collision.size() << "\n";
                    printProblems(std::cout, r.problems, "problems");
                } else if (!valid) {
                    std::cerr << label << ": INVALID\n";
                    printProblems(std::cerr, r.problems, "problems");
                }
                first = false;
                nlohmann::json j = jsonOf(file, r);
                j["valid"] = valid;
                j["object"] = rubble::tools::utf8Escaped(object.name);
                j["collision_parts"] = object.collision.size();
                j["collision_outside_hull"] = outside;
                doc["meshes"].push_back(std::move(j));
                if (!valid)
                    exitCode = std::max(exitCode, 1);
            }
            continue;
        }
        auto mesh = rubble::Result<rubble::Mesh>(objects.front().mesh);
        const rubble::MeshReport before = rubble::checkMesh(mesh.value(), checkOptions);
        if (!args.repair) {
            if (!args.json) {
                std::cout << file << ": " << (before.valid() ? "valid" : "INVALID") << "\n";
                printStats(std::cout, before);
                printProblems(std::cout, before.problems, "problems");
                if (!before.valid())
                    std::cout << "  to fix what can be fixed: rubble check --repair -o OUT " << quoteArg(file)
                              << "\n";
            } else if (!before.valid()) {
                std::cerr << file << ": INVALID\n";
                printProblems(std::cerr, before.problems, "problems");
            }
            doc["meshes"].push_back(jsonOf(file, before));
            if (!before.valid())
                exitCode = std::max(exitCode, 1);
            continue;
        }

        rubble::Mesh repaired = mesh.value();
        rubble::RepairOptions repairOptions;
        repairOptions.checkSelfIntersections = !args.noSelfIntersections;
        const rubble::RepairReport rep = rubble::repairMesh(repaired, repairOptions);
        const fs::path& out = outputs[i];
        text << file << ": " << (before.valid() ? "valid" : "INVALID") << " before repair\n";
        printProblems(text, before.problems, "problems");
        if (rep.fixed.empty()) {
            text << "  repair: nothing to fix\n";
        } else {
            text << "  repaired:\n";
            for (const std::string& f : rep.fixed)
                text << "    - " << f << "\n";
        }
        if (!rep.valid()) {
            // Nothing is written: a file named like a fix that is still invalid would be taken for one.
            text << "  not written: the repaired mesh is still INVALID\n";
            printProblems(text, rep.unrepaired, "could not repair");
            nlohmann::json j = jsonOf(file, rep.after);
            j["written"] = false;
            doc["meshes"].push_back(j);
            exitCode = std::max(exitCode, 1);
            continue;
        }
        rubble::Status written;
        {
            const rubble::tools::DeferSignals
                deferred; // a kill waits until the staging file is renamed or gone
            written = rubble::writeObj(out, repaired);
        }
        if (!written) {
            std::cerr << "rubble check: " << written.message() << "\n";
            doc["meshes"].push_back({{"file", rubble::tools::utf8Escaped(out.string())},
                                     {"error", rubble::tools::utf8Escaped(written.message())}});
            exitCode = 2;
            continue;
        }
        text << "  written to " << out.string() << ": valid\n";
        if (!args.json)
            printStats(std::cout, rep.after);
        doc["meshes"].push_back(jsonOf(out.string(), rep.after));
    }
    if (args.json)
        std::cout << rubble::tools::dumpJson(doc) << "\n";
    return exitCode;
}

const rubble::tools::Registrar registrar{
    {"check", "Check meshes: closed, manifold, oriented, self-intersections, volume; optionally repair",
     [](CLI::App& app) {
         auto args = std::make_shared<CheckArgs>();
         app.footer(
             "Exit codes: 0 every mesh is a valid solid, 1 a mesh is readable but invalid, 2 a file is "
             "unreadable or the command line is wrong.\nIn --json, self_intersections is the number of "
             "intersecting triangle pairs, or null when the test did not run.");
         app.add_option("meshes", args->files, "mesh files (.obj, .off, .stl, .ply, .3ds, .gltf, .glb)")
             ->required();
         app.add_flag("--json", args->json, "print a JSON document instead of text");
         app.add_flag("--repair", args->repair,
                      "weld vertices, drop degenerate/duplicate triangles, orient shells; write to -o");
         app.add_option("-o,--output", args->output,
                        "where --repair writes the repaired mesh (.obj; a folder for several meshes)");
         app.add_flag("--no-self-intersections", args->noSelfIntersections,
                      "skip the self-intersection test (faster on big meshes)");
         return [args] { return runCheck(*args); };
     }}};

} // namespace
