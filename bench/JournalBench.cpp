// `rubble-bench journal [--quick] [--impacts N] [--workers N] [--out DIR]`
//
// The journal and snapshots at scale: N impacts (default 1,000) recorded on the 10,092-triangle
// cube (shatter, 8 cells; each impact hits a live object chosen with probability ∝ volume, at its top
// corner, ten per frame), then
// replayed from the journal on a fresh world: ms per impact for recording (the fractures themselves) and for
// the replay, and whether the replay's geometry hash equals the recording's. Then the destroyed world's
// snapshot: bytes, encode, atomic save, load (read + decode + restore) in ms, and the journal's bytes against
// the snapshot's (what sending meshes instead of impacts would take); the load's thread CPU time too, since
// on a shared machine the wall time mostly measures waiting for a core. Deterministic mode, so both runs
// adopt each job at the same frame. Table on stdout, CSV in DIR/journal.csv, plot in DIR/journal.png; the
// timed snapshot file is written in the temporary folder. Exit code 2 when DIR cannot be a folder.
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "BenchUtil.hpp"
#include "Subcommand.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace {

// Collects the world's splits and commits each at once (no engine).
void adoptAll(rubble::DestructionWorld& world) {
    for (const rubble::FractureOutcome& split : world.collect())
        world.commit(split);
}

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using rubble::bench::fixed;
using rubble::bench::msSince;
using rubble::bench::threadCpuMs;

struct BenchArgs {
    bool quick = false;
    int impacts = 1000;
    int workers = -1;
    std::string out = rubble::bench::resultsDir();
};

rubble::DestructionWorld::Config worldConfig(int workers) {
    rubble::DestructionWorld::Config c;
    c.workers = workers;
    c.deterministic = true;
    c.delayFrames = 2;
    c.seed = 17;
    c.minPieceVolume = 1e-5;
    return c;
}

void addScene(rubble::DestructionWorld& world, int grid) {
    rubble::ObjectDesc cube;
    cube.mesh = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, grid);
    cube.fracture.pattern = rubble::CellPattern::Shatter;
    cube.fracture.cells = 8;
    cube.fracture.sizeLaw.base = cube.fracture.sizeLaw.minSize = cube.fracture.sizeLaw.maxSize = 0.6;
    cube.fracture.sizeLaw.scale = 0;
    (void)world.addObject(std::move(cube));
}

struct SnapshotTiming {
    std::size_t bytes = 0;
    double encodeMs = 0, saveMs = 0, decodeMs = 0, loadMs = 0;
    double loadCpuMs = 0; // CPU time of the loading thread: what the load costs when other processes compete
    bool same = false;    // the loaded world has the saved one's geometry hash
};

// Encodes, saves atomically to the file scratch, reads, decodes and restores into a fresh world.
SnapshotTiming timeSnapshot(const rubble::DestructionWorld& world,
                            const rubble::DestructionWorld::Config& config, const fs::path& scratch) {
    SnapshotTiming t;
    const auto s0 = Clock::now();
    const std::vector<std::uint8_t> bytes = rubble::encodeSnapshot(rubble::takeSnapshot(world));
    t.encodeMs = msSince(s0);
    t.bytes = bytes.size();
    const fs::path file = scratch;
    const auto w0 = Clock::now();
    if (!rubble::writeFileAtomic(file, bytes))
        return t;
    t.saveMs = msSince(w0);
    rubble::DestructionWorld loaded(config);
    const double c0 = threadCpuMs();
    const auto l0 = Clock::now();
    auto snap = rubble::loadSnapshot(file); // read + decode
    t.decodeMs = msSince(l0);
    const bool ok = snap && rubble::restoreSnapshot(loaded, std::move(*snap));
    t.loadMs = msSince(l0);
    t.loadCpuMs = threadCpuMs() - c0;
    fs::remove(file);
    t.same = ok && loaded.geometryHash() == world.geometryHash();
    return t;
}

int runBench(const BenchArgs& args) {
    if (!rubble::bench::makeResultsDir(args.out))
        return 2;
    // The timed snapshot file goes to the temporary folder, never into the results (or source) folder.
    std::error_code ec;
    const fs::path scratch =
        fs::temp_directory_path(ec) / ("rubble-journal-bench-" + std::to_string(::getpid()) + ".rsnap");
    const int impacts = args.quick ? 30 : args.impacts;
    const int grid = args.quick ? 7 : 29; // 588 or 10,092 triangles
    const rubble::bench::CpuMeter cpu;
    // Record: impacts on random live objects, as a game would submit them.
    rubble::DestructionWorld recorder(worldConfig(args.workers));
    addScene(recorder, grid);
    const std::size_t triangles = recorder.object(1)->mesh.triangleCount();
    std::vector<rubble::JournalEvent> events;
    recorder.setJournalSink([&](const rubble::JournalEvent& e) { events.push_back(e); });
    rubble::Rng rng(2026);
    const auto r0 = Clock::now();
    int submitted = 0;
    while (submitted < impacts) {
        for (int k = 0; k < 10 && submitted < impacts; ++k) {
            // a live object chosen with probability ∝ volume (so that large pieces keep breaking)
            const std::vector<rubble::ObjectId> live = recorder.objects();
            double total = 0;
            for (rubble::ObjectId o : live)
                total += recorder.object(o)->mass.volume;
            double pick = rng.uniform(0, total);
            rubble::ObjectId id = live.back();
            for (rubble::ObjectId o : live) {
                pick -= recorder.object(o)->mass.volume;
                if (pick < 0) {
                    id = o;
                    break;
                }
            }
            const rubble::Aabb b = recorder.object(id)->mesh.bounds();
            if (recorder.submitImpact(id, rubble::Impact{b.hi, {0.577, 0.577, 0.577}, 500}))
                ++submitted;
        }
        recorder.beginFrame();
        adoptAll(recorder);
    }
    while (recorder.jobsInFlight() > 0) {
        recorder.beginFrame();
        adoptAll(recorder);
    }
    const double recordMs = msSince(r0);
    // Replay from the journal's bytes on a fresh world.
    const rubble::JournalFile journal{rubble::journalHeaderOf(worldConfig(args.workers), "cube"), events};
    const std::vector<std::uint8_t> journalBytes = rubble::encodeJournal(journal);
    rubble::DestructionWorld replayer(worldConfig(args.workers));
    addScene(replayer, grid);
    const auto p0 = Clock::now();
    auto decoded = rubble::decodeJournal(journalBytes.data(), journalBytes.size(), "journal");
    if (!decoded) {
        std::cerr << "journal: " << decoded.error().message << "\n";
        return 1;
    }
    rubble::JournalPlayer player(replayer);
    for (const rubble::JournalEvent& e : decoded->events)
        if (!player.receive(e)) {
            std::cerr << "journal: replay refused an event\n";
            return 1;
        }
    if (!player.advanceTo(recorder.frame())) {
        std::cerr << "journal: replay failed\n";
        return 1;
    }
    const double replayMs = msSince(p0);
    const bool same = replayer.geometryHash() == recorder.geometryHash();
    const SnapshotTiming cubeSnap = timeSnapshot(replayer, worldConfig(args.workers), scratch);
    // A world of many pieces: a grid of small boxes, each shattered once, until it holds targetPieces
    // objects.
    const int targetPieces = args.quick ? 200 : 5000;
    rubble::DestructionWorld pieces(worldConfig(args.workers));
    for (int i = 0; pieces.objects().size() < static_cast<std::size_t>(targetPieces); ++i) {
        rubble::ObjectDesc box;
        const rubble::Vec3 c{1.2 * (i % 40), 0, 1.2 * (i / 40)};
        box.mesh =
            rubble::makeSubdividedBox(c - rubble::Vec3{0.5, 0.5, 0.5}, c + rubble::Vec3{0.5, 0.5, 0.5}, 2);
        box.fracture.pattern = rubble::CellPattern::Shatter;
        box.fracture.cells = 8;
        box.fracture.sizeLaw.base = box.fracture.sizeLaw.minSize = box.fracture.sizeLaw.maxSize = 0.9;
        box.fracture.sizeLaw.scale = 0;
        const rubble::ObjectId id = *pieces.addObject(std::move(box));
        (void)pieces.submitImpact(id, rubble::Impact{c + rubble::Vec3{0.5, 0.2, 0.1}, {1, 0, 0}, 100});
        pieces.beginFrame();
        adoptAll(pieces);
        if (i > 20 * targetPieces)
            break;
    }
    pieces.waitIdle();
    for (int i = 0; i < 4; ++i) {
        pieces.beginFrame();
        adoptAll(pieces);
    }
    const SnapshotTiming pieceSnap = timeSnapshot(pieces, worldConfig(args.workers), scratch);
    const double otherCpu = cpu.read().other;

    const double journalPerImpact = double(journalBytes.size()) / double(impacts);
    rubble::bench::Table table{{"world", "objects", "record ms/impact", "replay ms/impact", "replay = record",
                                "journal B/impact", "snapshot KB", "encode ms", "save ms", "read+decode ms",
                                "load ms", "load CPU ms", "load = saved"},
                               {}};
    rubble::bench::Table csv{
        {"world", "impacts", "objects", "workers", "record_ms_per_impact", "replay_ms_per_impact",
         "replay_hash_equal", "journal_bytes_per_impact", "snapshot_bytes", "snapshot_bytes_per_impact",
         "snapshot_vs_event_ratio", "snapshot_encode_ms", "snapshot_save_ms", "snapshot_read_decode_ms",
         "snapshot_load_ms", "snapshot_load_cpu_ms", "snapshot_load_hash_equal", "other_cpu_cores"},
        {}};
    const std::string cubeName =
        "cube_" + std::to_string(triangles) + "_" + std::to_string(impacts) + "_impacts";
    const std::string piecesName = "boxes_shattered_" + std::to_string(pieces.objects().size()) + "_pieces";
    const double snapPerImpact = double(cubeSnap.bytes) / double(impacts);
    table.rows.push_back({cubeName, std::to_string(replayer.objects().size()), fixed(recordMs / impacts),
                          fixed(replayMs / impacts), same ? "yes" : "NO", fixed(journalPerImpact, 1),
                          fixed(cubeSnap.bytes / 1024.0, 0), fixed(cubeSnap.encodeMs, 1),
                          fixed(cubeSnap.saveMs, 1), fixed(cubeSnap.decodeMs, 1), fixed(cubeSnap.loadMs, 1),
                          fixed(cubeSnap.loadCpuMs, 1), cubeSnap.same ? "yes" : "NO"});
    table.rows.push_back({piecesName, std::to_string(pieces.objects().size()), "", "", "", "",
                          fixed(pieceSnap.bytes / 1024.0, 0), fixed(pieceSnap.encodeMs, 1),
                          fixed(pieceSnap.saveMs, 1), fixed(pieceSnap.decodeMs, 1),
                          fixed(pieceSnap.loadMs, 1), fixed(pieceSnap.loadCpuMs, 1),
                          pieceSnap.same ? "yes" : "NO"});
    rubble::bench::printTable(table);
    std::cout << "snapshot of the cube world: " << fixed(snapPerImpact, 0) << " bytes per impact, "
              << fixed(snapPerImpact / 48, 0) << "x the 48 bytes of a journal event\n";
    csv.rows.push_back({cubeName, std::to_string(impacts), std::to_string(replayer.objects().size()),
                        std::to_string(args.workers), fixed(recordMs / impacts, 4),
                        fixed(replayMs / impacts, 4), same ? "1" : "0", fixed(journalPerImpact, 2),
                        std::to_string(cubeSnap.bytes), fixed(snapPerImpact, 1), fixed(snapPerImpact / 48, 1),
                        fixed(cubeSnap.encodeMs, 3), fixed(cubeSnap.saveMs, 3), fixed(cubeSnap.decodeMs, 3),
                        fixed(cubeSnap.loadMs, 3), fixed(cubeSnap.loadCpuMs, 3), cubeSnap.same ? "1" : "0",
                        fixed(otherCpu, 2)});
    csv.rows.push_back({piecesName, "", std::to_string(pieces.objects().size()), std::to_string(args.workers),
                        "", "", "", "", std::to_string(pieceSnap.bytes), "", "", fixed(pieceSnap.encodeMs, 3),
                        fixed(pieceSnap.saveMs, 3), fixed(pieceSnap.decodeMs, 3), fixed(pieceSnap.loadMs, 3),
                        fixed(pieceSnap.loadCpuMs, 3), pieceSnap.same ? "1" : "0", fixed(otherCpu, 2)});
    if (!rubble::bench::writeCsv(fs::path(args.out) / "journal.csv", csv))
        return 1;
    std::ostringstream data;
    data << "0 \"record ms/impact\" " << recordMs / impacts << "\n1 \"replay ms/impact\" "
         << replayMs / impacts << "\n2 \"load " << pieces.objects().size() << " pieces (ms)\" "
         << pieceSnap.loadMs << "\n";
    rubble::bench::plotPng(
        args.out, "journal", data.str(),
        "set style fill solid 0.6\nset boxwidth 0.6\nset ylabel 'ms'\nset grid y\n"
        "set title 'Journal replay and snapshot load'\nplot $DATA u 1:3:xtic(2) w boxes notitle");
    const bool loadSame = cubeSnap.same && pieceSnap.same;
    return same && loadSame ? 0 : 1;
}

const rubble::tools::Registrar registrar{
    {"journal", "Journal replay and snapshot save/load of a world destroyed by N impacts", [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_flag("--quick", args->quick, "30 impacts on a 588-triangle cube (CI smoke run)");
         app.add_option("--impacts", args->impacts, "impacts to record and replay")
             ->check(CLI::Range(1, 1000000));
         app.add_option("--workers", args->workers, "fracture workers (-1 automatic)");
         app.add_option("--out", args->out, "folder for journal.csv and journal.png");
         return [args] { return runBench(*args); };
     }}};

} // namespace
