// `rubble-bench netplay SCENE.cfg [--seconds T] [--clients N] [--shots-per-second R] [--workers W] [--seed S]
//  [--late-join F] [--json]`
//
// Loopback multiplayer as separate processes (issue #17): this process hosts the scene on the Bullet binding
// in deterministic mode (fixed 1/60 s frames paced at 60 Hz, seeded projectiles at destructible bodies), and
// starts N clients (`rubble-bench netplay-client`, this executable again) that connect over ENet to
// 127.0.0.1; the last one joins at fraction F of the run (default 1/3: snapshot + journal tail), the others
// at once. Each frame the host publishes the journal events and a sync with its geometry hash; every 6th
// frame the dynamic bodies' placements (10 Hz). Each client checks its geometry hash at every sync. After T
// seconds the host stops firing, lets the fracture jobs finish, waits (at most 10 s) for every client to
// confirm the last sync, closes the connections; the clients print their figures and exit (a client still
// running 15 s later is killed). Bounded in time and packets; loopback addresses only.
//
// Reports impacts (host journal impacts), geometry_bytes_per_impact (journal event messages sent to one
// client / impacts: 48 bytes per event plus a 5-byte header per frame's batch; removals are events too),
// transform_bytes_per_s (placement bytes sent to one client per second), mismatched_hashes (Σ over clients of
// syncs whose hash differed, plus hashes reported back to the host that differed), late_join_ms (connect →
// snapshot loaded, last client), snapshot_bytes, and the clients' sync counts.
#include "Subcommand.hpp"

#if defined(RUBBLE_HAVE_BULLET) && defined(RUBBLE_HAVE_ENET)

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "BenchUtil.hpp"
#include "rubble/DestructionRuntime.hpp"
#include "rubble/Random.hpp"
#include "rubble/SceneConfig.hpp"
#include "rubble/SceneLoader.hpp"
#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/enet/NetClient.hpp"
#include "rubble/enet/NetHost.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Args {
    std::string file;
    double seconds = 60;
    int clients = 2;
    double shotsPerSecond = 10;
    int workers = -1;
    std::uint64_t seed = 1;
    double lateJoin = 1.0 / 3;
    bool json = false;
    int port = 0; // client: the host's port
};

rubble::DestructionRuntime::Config runtimeConfig(const Args& a) {
    rubble::DestructionRuntime::Config rc;
    rc.world.workers = a.workers;
    rc.world.deterministic = true;
    rc.world.seed = a.seed;
    return rc;
}

// A projectile at a random destructible body (uniform), from 30 m away, slightly from above.
void fire(rubble::DestructionRuntime& runtime, rubble::Rng& rng) {
    using namespace rubble;
    std::vector<const BodyRecord*> targets;
    for (BodyId id : runtime.bodies()) {
        const BodyRecord* b = runtime.body(id);
        if (b->hasObject && runtime.world().object(b->object) &&
            runtime.world().object(b->object)->destructible)
            targets.push_back(b);
    }
    if (targets.empty())
        return;
    const BodyRecord* t = targets[static_cast<std::size_t>(rng.next() % targets.size())];
    const Frame f = runtime.motion(t->id).transform * t->objectToBody.inverse();
    const Aabb box = runtime.world().object(t->object)->mesh.bounds();
    const Vec3 at = f.apply(box.center());
    const double phi = rng.uniform(0, 2 * 3.14159265358979);
    const Vec3 dir = normalized(Vec3{std::cos(phi), 0.3, std::sin(phi)});
    runtime.fireProjectile(at + dir * (30 + box.diagonal()), dir * -120.0, 2, 0.25);
}

struct Child {
    pid_t pid = -1;
    int out = -1; // read end of its stdout
};

Child spawn(const Args& a, std::uint16_t port) {
    int fds[2];
    if (pipe(fds) != 0)
        return {};
    const pid_t pid = fork();
    if (pid == 0) {
        dup2(fds[1], STDOUT_FILENO);
        close(fds[0]);
        close(fds[1]);
        const std::string p = std::to_string(port), w = std::to_string(a.workers), s = std::to_string(a.seed),
                          t = std::to_string(a.seconds + 60);
        execl("/proc/self/exe", "rubble-bench", "netplay-client", "--port", p.c_str(), "--workers", w.c_str(),
              "--seed", s.c_str(), "--seconds", t.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    close(fds[1]);
    return {pid, fds[0]};
}

std::string readAll(int fd) {
    std::string s;
    char buf[4096];
    for (ssize_t n; (n = read(fd, buf, sizeof buf)) > 0;)
        s.append(buf, static_cast<std::size_t>(n));
    close(fd);
    return s;
}

int runHost(const Args& a) {
    using namespace rubble;
    Result<SceneConfig> scene = parseSceneConfig(a.file);
    if (!scene) {
        std::cerr << "rubble-bench netplay: " << scene.error().message << "\n";
        return 2;
    }
    const DestructionRuntime::Config rc = runtimeConfig(a);
    bullet::PhysicsWorld physics;
    bullet::BulletBinding binding(physics);
    DestructionRuntime runtime(binding, rc);
    SceneLoadOptions lo;
    lo.loadVehicle = false;
    (void)loadScene(*scene, runtime, lo);
    auto server = net::NetHost::listen(runtime.world(), rc.world, "127.0.0.1", 0, a.clients);
    if (!server) {
        std::cerr << "rubble-bench netplay: " << server.error().message << "\n";
        return 1;
    }
    net::NetHost& host = **server;
    host.setPlacementSource([&] { return runtime.placements(); });
    std::vector<Child> children;
    for (int i = 0; i + 1 < a.clients; ++i)
        children.push_back(spawn(a, host.port()));
    Rng rng(mixSeed(a.seed, 0x4E7));
    const long frames = std::max(1L, std::lround(a.seconds * 60));
    const long lateFrame = a.clients > 0 ? std::lround(static_cast<double>(frames) * a.lateJoin) : -1;
    const rubble::bench::CpuMeter cpu; // the clients are other processes: "other" includes them
    const auto start = Clock::now();
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / 60));
    long shots = 0, f = 0;
    auto frame = [&](bool firing) {
        std::this_thread::sleep_until(start + period * f);
        const long due = static_cast<long>(static_cast<double>(f) * a.shotsPerSecond / 60.0);
        for (; firing && shots < due; ++shots)
            fire(runtime, rng);
        runtime.stepFrame();
        host.publish();
        if (f % 6 == 0)
            host.publishPlacements(runtime.placements());
        host.service(0);
        ++f;
    };
    for (; f < frames;) {
        if (f == lateFrame)
            children.push_back(spawn(a, host.port()));
        frame(true);
    }
    for (int i = 0; i < 600 && runtime.world().jobsInFlight() > 0; ++i)
        frame(false);
    // Every client confirms the last sync (or 10 s pass).
    const long long expected = host.stats().syncs;
    for (const auto t0 = Clock::now();
         host.stats().acks < expected && Clock::now() - t0 < std::chrono::seconds(10);)
        host.service(5);
    const net::HostStats hs = host.stats();
    const double runSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    const std::uint64_t hostHash = runtime.world().geometryHash();
    server->reset(); // closes the connections: the clients report and exit
    nlohmann::json clients = nlohmann::json::array();
    long long mismatched = hs.mismatchedHashes;
    double lateJoinMs = -1;
    bool allConverged = true;
    for (Child& c : children) {
        const std::string out = readAll(c.out);
        int status = 0;
        for (int i = 0; i < 1500 && waitpid(c.pid, &status, WNOHANG) == 0; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (waitpid(c.pid, &status, WNOHANG) == 0) {
            kill(c.pid, SIGKILL);
            waitpid(c.pid, &status, 0);
        }
        nlohmann::json j = nlohmann::json::parse(out, nullptr, false);
        if (j.is_discarded() || !j.is_object()) {
            j = {{"error", "no report"}, {"output", out}};
            allConverged = false;
        } else {
            mismatched += j.value("mismatched_hashes", 0LL);
            lateJoinMs = j.value("join_ms", -1.0);
            allConverged =
                allConverged && j.value("geometry_hash", std::string()) == std::to_string(hostHash);
        }
        clients.push_back(j);
    }
    const double impacts =
        static_cast<double>(hs.impactEvents) / std::max(1, static_cast<int>(children.size()));
    const double perClientEventBytes =
        static_cast<double>(hs.eventBytes) / std::max<std::size_t>(1, children.size());
    nlohmann::json r;
    r["scene"] = a.file;
    r["seconds"] = runSeconds;
    r["clients"] = a.clients;
    r["impacts"] = runtime.counters().impacts;
    r["fractures"] = runtime.counters().fractures;
    r["geometry_bytes_per_impact"] = impacts > 0 ? perClientEventBytes / impacts : 0;
    r["transform_bytes_per_s"] =
        static_cast<double>(hs.placementBytes) / std::max<std::size_t>(1, children.size()) / runSeconds;
    r["mismatched_hashes"] = mismatched;
    r["late_join_ms"] = lateJoinMs;
    r["snapshot_bytes"] = hs.snapshotBytes / std::max<long long>(1, hs.joins);
    r["final_hashes_equal"] = allConverged;
    r["host_geometry_hash"] = std::to_string(hostHash);
    r["client_reports"] = clients;
    const auto use = cpu.read();
    r["cpu_cores"] = {{"own", use.own}, {"other", use.other}};
    if (a.json) {
        std::cout << r.dump() << "\n";
    } else {
        std::cout << "netplay " << a.file << ": " << r["impacts"] << " impacts, " << r["fractures"]
                  << " fractures, " << r["geometry_bytes_per_impact"] << " geometry bytes/impact, "
                  << r["transform_bytes_per_s"] << " transform bytes/s, " << mismatched
                  << " mismatched hashes, "
                  << "late join " << lateJoinMs
                  << " ms, final hashes equal: " << (allConverged ? "yes" : "NO") << "\n";
    }
    return mismatched == 0 && allConverged && !children.empty() ? 0 : 1;
}

int runClient(const Args& a) {
    using namespace rubble;
    const DestructionRuntime::Config rc = runtimeConfig(a);
    DestructionWorld world(rc.world);
    auto client = net::NetClient::connect(world, rc.world, "127.0.0.1", static_cast<std::uint16_t>(a.port));
    if (!client) {
        std::cout << nlohmann::json{{"error", client.error().message}}.dump() << "\n";
        return 1;
    }
    std::string ending = "time limit";
    for (const auto t0 = Clock::now(); Clock::now() - t0 < std::chrono::duration<double>(a.seconds);) {
        if (Status s = (*client)->service(5); !s) {
            ending = s.message();
            break;
        }
    }
    const net::ClientStats& st = (*client)->stats();
    nlohmann::json j{{"joined", st.joined},
                     {"join_ms", st.joinMs},
                     {"events", st.events},
                     {"syncs", st.syncs},
                     {"mismatched_hashes", st.mismatchedHashes},
                     {"frame", st.frame},
                     {"geometry_hash", std::to_string(world.geometryHash())},
                     {"placements", st.placements},
                     {"placement_bytes", st.placementBytes},
                     {"ending", ending}};
    std::cout << j.dump() << "\n";
    return st.joined ? 0 : 1;
}

const rubble::tools::Registrar host{
    {"netplay", "Loopback multiplayer: a host and client processes over ENet on 127.0.0.1",
     [](CLI::App& app) {
         auto a = std::make_shared<Args>();
         app.add_option("scene", a->file, "world.cfg scene")->required()->check(CLI::ExistingFile);
         app.add_option("--seconds", a->seconds, "seconds of continuous fire")
             ->check(CLI::Range(0.1, 3600.0));
         app.add_option("--clients", a->clients, "client processes")->check(CLI::Range(1, 8));
         app.add_option("--shots-per-second", a->shotsPerSecond, "projectiles per second");
         app.add_option("--workers", a->workers, "fracture workers of host and clients (-1 automatic)");
         app.add_option("--seed", a->seed, "world and firing seed");
         app.add_option("--late-join", a->lateJoin, "the last client joins at this fraction of the run")
             ->check(CLI::Range(0.0, 1.0));
         app.add_flag("--json", a->json, "one JSON object on stdout");
         return [a] { return runHost(*a); };
     }}};

const rubble::tools::Registrar client{
    {"netplay-client",
     "(started by `netplay`) a client process: follows the host, prints its figures as JSON",
     [](CLI::App& app) {
         auto a = std::make_shared<Args>();
         app.add_option("--port", a->port, "the host's port on 127.0.0.1")
             ->required()
             ->check(CLI::Range(1, 65535));
         app.add_option("--workers", a->workers, "fracture workers");
         app.add_option("--seed", a->seed, "world seed (the host's)");
         app.add_option("--seconds", a->seconds, "give up after this many seconds");
         return [a] { return runClient(*a); };
     }}};

} // namespace

#endif
