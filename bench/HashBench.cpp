// `rubble-bench hash [--sizes N...] [--runs R] [--quick] [--label TEXT] [--out DIR]`
//
// Mesh::hash (64-bit words in four lanes) beside the former byte-wise FNV-1a (detail::formerMeshHash) on the
// same meshes in one run: geodesic spheres of about N triangles with per-corner normals and texture
// coordinates, as the pieces of a game carry them. The two are timed alternately, R runs each; medians.
// Table on stdout, mesh_hash.csv (rows of other labels kept) and mesh_hash.png in DIR.
#include <algorithm>
#include <iostream>
#include <memory>
#include <sstream>

#include "BenchUtil.hpp"
#include "MegaMeshes.hpp"
#include "Subcommand.hpp"
#include "geometry/FormerMeshHash.hpp"

namespace {

using rubble::bench::fixed;

struct BenchArgs {
    std::vector<std::size_t> sizes{10000, 250000, 1000000};
    int runs = 9;
    bool quick = false;
    std::string label = "current";
    std::string out = rubble::bench::resultsDir();
};

int runBench(BenchArgs args) {
    if (args.quick) {
        args.sizes = {2000};
        args.runs = 3;
    }
    rubble::bench::Table table{
        {"label", "triangles", "mbytes", "former_fnv1a_ms", "words_ms", "speedup", "other_cpu_cores"}, {}};
    const std::filesystem::path csvPath = std::filesystem::path(args.out) / "mesh_hash.csv";
    table.rows = rubble::bench::rowsOfOtherLabels(csvPath, args.label, table.header.size());
    for (std::size_t size : args.sizes) {
        const rubble::Mesh mesh =
            rubble::bench::withFlatAttributes(rubble::bench::megaMesh("geosphere", size));
        const double bytes = static_cast<double>(
            mesh.positions.size() * sizeof(rubble::Vec3) + mesh.triangles.size() * sizeof(rubble::Triangle) +
            mesh.normals.size() * sizeof(rubble::Vec3f) + mesh.uvs.size() * sizeof(rubble::Vec2f));
        std::uint64_t sink = 0;
        std::vector<double> former, words;
        const rubble::bench::CpuMeter cpu;
        for (int r = 0; r < args.runs; ++r) {
            auto t0 = std::chrono::steady_clock::now();
            sink ^= rubble::detail::formerMeshHash(mesh);
            former.push_back(rubble::bench::msSince(t0));
            t0 = std::chrono::steady_clock::now();
            sink ^= mesh.hash();
            words.push_back(rubble::bench::msSince(t0));
        }
        const double f = rubble::bench::stats(former).median, w = rubble::bench::stats(words).median;
        table.rows.push_back({args.label, std::to_string(mesh.triangles.size()), fixed(bytes / 1e6, 2),
                              fixed(f), fixed(w), fixed(w > 0 ? f / w : 0, 1), fixed(cpu.read().other, 2)});
        if (sink == 0x5EED) // keeps the hashes from being optimised away
            std::cout << ' ';
    }
    rubble::bench::printTable(table);
    if (!rubble::bench::makeResultsDir(args.out) || !rubble::bench::writeCsv(csvPath, table))
        return 1;
    std::ostringstream data;
    for (std::size_t i = 0; i < table.rows.size(); ++i) {
        const auto& c = table.rows[i];
        data << i << " \"" << c[0] << " " << c[1] << "\" " << c[3] << " " << c[4] << "\n";
    }
    rubble::bench::plotPng(args.out, "mesh_hash", data.str(),
                           "set style data histograms\nset style fill solid 0.6\nset logscale y\n"
                           "set ylabel 'ms per hash (median)'\nset grid y\nset xtics rotate by -20\n"
                           "set title 'Mesh::hash: former byte-wise FNV-1a against 64-bit words, one run'\n"
                           "plot $DATA u 3:xtic(2) title 'former FNV-1a', $DATA u 4 title 'words, 4 lanes'");
    return 0;
}

const rubble::tools::Registrar registrar{
    {"hash", "Mesh::hash beside the former byte-wise FNV-1a, on meshes with per-corner attributes",
     [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_option("--sizes", args->sizes, "triangles of each geodesic sphere");
         app.add_option("--runs", args->runs, "timed runs of each hash per mesh")->check(CLI::Range(1, 1000));
         app.add_flag("--quick", args->quick, "one 2k-triangle mesh, 3 runs (CI smoke run)");
         app.add_option("--label", args->label, "names this run's rows in mesh_hash.csv");
         app.add_option("--out", args->out, "folder for mesh_hash.csv and mesh_hash.png");
         return [args] { return runBench(*args); };
     }}};

} // namespace
