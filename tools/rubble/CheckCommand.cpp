// `rubble check MESH... [--json] [--repair -o OUT] [--no-self-intersections]`
//
// Exit codes: 0 all meshes valid (after repair, with --repair); 1 some mesh readable but invalid;
// 2 some mesh unreadable, or a usage error. In --json mode stdout holds only the JSON document
// {"meshes":[{"file","valid","problems":[...],"vertices","triangles","closed","manifold","oriented",
// "self_intersections","volume","center_of_mass":[x,y,z],"bbox":[[lo],[hi]]}]}, where self_intersections is
// the number of intersecting triangle pairs or null when the test did not run; an unreadable file appears as
// {"file","error"}. With --repair the entries describe the repaired meshes, "file" being the path written (or
// {"file","error"} when it could not be written; exit 2). Two inputs with the same stem are refused with
// --repair into a folder. Outputs are written through a staging file and renamed.
// Problems and repair notes go to stderr in --json mode.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "JsonText.hpp"
#include "Staging.hpp"
#include "Subcommand.hpp"
#include "rubble/MeshCheck.hpp"
#include "rubble/MeshIO.hpp"
#include "rubble/MeshRepair.hpp"

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
        auto mesh = rubble::readMesh(file);
        if (!mesh) {
            std::cerr << "rubble check: " << mesh.error().message << "\n";
            if (args.json)
                doc["meshes"].push_back({{"file", rubble::tools::utf8Escaped(file)},
                                         {"error", rubble::tools::utf8Escaped(mesh.error().message)}});
            exitCode = 2;
            continue;
        }
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
        text << "  written to " << out.string() << ": " << (rep.valid() ? "valid" : "still INVALID") << "\n";
        if (!args.json)
            printStats(std::cout, rep.after);
        printProblems(text, rep.unrepaired, "could not repair");
        doc["meshes"].push_back(jsonOf(out.string(), rep.after));
        if (!rep.valid())
            exitCode = std::max(exitCode, 1);
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
