// `rubble-server SCENE.cfg [--port P] [--clients N] [--seconds T] [--workers W] [--seed S] [--shot-rate R]
//  [--placement-budget BYTES] [--placement-peak BYTES] [--placement-reserve BYTES] [--placement-hz H]`
//
// A dedicated, headless netplay server (docs/netplay.md, 'Dedicated server'): it loads a world.cfg scene on
// the Bullet binding in deterministic mode, listens on 127.0.0.1:P (0 = any free port) and runs the
// authoritative world at 60 Hz. The world changes only through clients' shots that pass the host's checks
// (NetHost::setShotHandler: rate, speed, origin); every frame it publishes the journal and a sync, every 3rd
// the placements (H = 20 a second; the budget's bytes per publish scaled to the same bytes a second). After T
// seconds (0 = until SIGINT or SIGTERM) it lets the fracture jobs finish, waits for the clients to confirm
// the last sync, tells them it stops (NetHost::close) and prints one JSON line of totals with its final
// geometry hash. Prints "rubble-server: listening on 127.0.0.1:PORT" once it serves.
#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/enet/NetHost.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/SceneLoader.hpp"

namespace {

std::atomic<bool> stopRequested{false};

void requestStop(int) {
    stopRequested = true;
}

} // namespace

int main(int argc, char** argv) {
    using namespace rubble;
    using Clock = std::chrono::steady_clock;
    CLI::App app{"rubble-server: a headless, authoritative netplay host for a world.cfg scene"};
    std::string file;
    int port = 7777, clients = 12, workers = -1;
    net::PlacementBudget budget;
    double seconds = 0, shotRate = 10;
    std::uint64_t seed = 1;
    app.add_option("scene", file, "world.cfg scene")->required()->check(CLI::ExistingFile);
    app.add_option("--port", port, "UDP port on 127.0.0.1 (0: any free port)")->check(CLI::Range(0, 65535));
    app.add_option("--clients", clients, "most clients at once")->check(CLI::Range(1, 64));
    app.add_option("--seconds", seconds, "serve this long (0: until SIGINT or SIGTERM)")
        ->check(CLI::Range(0.0, 1e6));
    app.add_option("--workers", workers, "fracture workers (-1 automatic)");
    app.add_option("--seed", seed, "world seed");
    app.add_option("--shot-rate", shotRate, "shots per second each client may fire")
        ->check(CLI::Range(0.0, 100.0));
    app.add_option("--placement-budget", budget.mean, "placement bytes per client per 10 Hz publish, mean")
        ->check(CLI::Range(100, 1000000));
    app.add_option("--placement-peak", budget.peak, "placement bytes per client in one publish, at most")
        ->check(CLI::Range(100, 1000000));
    app.add_option("--placement-reserve", budget.reserve, "placement bytes a client may have saved up")
        ->check(CLI::Range(100, 10000000));
    double placementHz = 20;
    app.add_option("--placement-hz", placementHz, "placements publishes a second")
        ->check(CLI::Range(1.0, 60.0));
    CLI11_PARSE(app, argc, argv);

    Result<SceneConfig> scene = parseSceneConfig(file);
    if (!scene) {
        std::cerr << "rubble-server: " << scene.error().message << "\n";
        return 2;
    }
    DestructionRuntime::Config rc;
    rc.world.workers = workers;
    rc.world.deterministic = true;
    rc.world.seed = seed;
    bullet::PhysicsWorld physics;
    bullet::BulletBinding binding(physics);
    DestructionRuntime runtime(binding, rc);
    SceneLoadOptions lo;
    lo.loadVehicle = false; // clients load the scene the same way (their snapshot names these objects by id)
    const LoadedScene loaded = loadScene(*scene, runtime, lo);
    for (const std::string& w : loaded.warnings)
        std::cerr << "rubble-server: " << w << "\n";
    auto server =
        net::NetHost::listen(runtime, rc.world, "127.0.0.1", static_cast<std::uint16_t>(port), clients);
    if (!server) {
        std::cerr << "rubble-server: " << server.error().message << "\n";
        return 1;
    }
    net::NetHost& host = **server;
    host.setPlacementSource([&] { return runtime.placements(); });
    const long placementEvery = std::max(1L, std::lround(60.0 / placementHz)); // frames between publishes
    budget.mean =
        budget.mean * static_cast<std::size_t>(placementEvery) / 6; // per 10 Hz publish → per publish
    budget.peak = budget.peak * static_cast<std::size_t>(placementEvery) / 6;
    host.setPlacementBudget(budget);
    std::vector<net::ShotRequest> shots;
    net::ShotRules rules;
    rules.perSecond = shotRate;
    rules.burst = std::max(1.0, shotRate);
    host.setShotHandler([&](const net::ShotRequest& r) { shots.push_back(r); }, rules);
    std::signal(SIGINT, requestStop);
    std::signal(SIGTERM, requestStop);
    std::printf("rubble-server: listening on 127.0.0.1:%u, %zu objects\n", host.port(),
                loaded.objects.size());
    std::fflush(stdout);

    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / 60));
    const auto start = Clock::now();
    long frame = 0;
    const auto step = [&] {
        for (const net::ShotRequest& r : shots)
            runtime.fireProjectile(r.origin, r.velocity, 2, 0.25);
        shots.clear();
        runtime.stepFrame();
        host.publish();
        if (frame % placementEvery == 0)
            host.publishPlacements(runtime.placements());
        host.service(0);
        ++frame;
    };
    while (!stopRequested &&
           (seconds <= 0 || Clock::now() - start < std::chrono::duration<double>(seconds))) {
        for (auto due = start + period * frame; Clock::now() < due;) // serving the network meanwhile
            host.service(
                static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(due - Clock::now()).count()));
        step();
    }
    shots.clear(); // no more shots: the jobs in flight finish
    for (int i = 0; i < 600 && runtime.world().jobsInFlight() > 0; ++i)
        step();
    const bool confirmed = host.finish(10000);
    const bool closed = host.close(5000);
    const net::HostStats& hs = host.stats();
    const nlohmann::json summary{{"frames", runtime.world().frame()},
                                 {"joins", hs.joins},
                                 {"impacts", runtime.counters().impacts},
                                 {"fractures", runtime.counters().fractures},
                                 {"shots_accepted", hs.shotsAccepted},
                                 {"shots_refused", hs.shotsRefused},
                                 {"mismatched_hashes", hs.mismatchedHashes},
                                 {"snapshot_bytes", hs.snapshotBytes},
                                 {"snapshot_objects_by_reference", hs.snapshotObjectsByReference},
                                 {"clients_confirmed_last_sync", confirmed},
                                 {"clients_told", closed},
                                 {"geometry_hash", std::to_string(runtime.world().geometryHash())}};
    std::printf("%s\n", summary.dump().c_str());
    return hs.mismatchedHashes == 0 ? 0 : 1;
}
