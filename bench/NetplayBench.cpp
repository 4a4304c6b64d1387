// `rubble-bench netplay SCENE.cfg [--seconds T] [--clients N] [--shots-per-second R] [--workers W] [--seed S]
//  [--late-join F] [--delay-ms D] [--jitter-ms J] [--loss L] [--burst B] [--partition-at A --partition-s P]
//  [--placement-budget BYTES] [--placement-peak BYTES] [--placement-reserve BYTES] [--placement-hz H]
//  [--resync-frames N] [--snapshot-cache] [--json] [--out DIR]`
//
// Multiplayer as separate processes over a network that misbehaves: this process hosts the scene on the
// Bullet binding in deterministic mode (fixed 1/60 s frames paced at 60 Hz, seeded projectiles at
// destructible bodies) and starts N clients (`rubble-bench netplay-client`, this executable again), each
// connecting over ENet to 127.0.0.1 through its own seeded UdpRelay (one-way delay D ms with jitter J ms each
// way, loss L with mean bursts of B datagrams, and a partition of P s at A s into the run); the last one
// joins at fraction F of the run (default 1/3: snapshot + journal tail), the others at once. Each client
// loads the scene itself first, so the host sends its unbroken objects by id (--no-base: the snapshot brings
// all). Each frame the host publishes the journal events and a sync with its geometry hash; every 6th frame
// the placements (10 Hz; H a second with --placement-hz, the budget scaled to the same bytes a second). After
// T seconds the host stops firing, lets the fracture jobs finish, waits (at most 10 s) for every client to
// confirm the last sync, closes the connections; the clients print their figures and exit (a client still
// running 15 s later is killed). Bounded in time and packets; loopback addresses only.
//
// Reports per client the kbps the host offered its link (UDP payload: ENet headers included, IP/UDP headers
// not), mean and 99th-percentile second, its mismatched hashes and placement error (the client's interpolated
// placement one placement period behind its latest sync against the host's at that frame, every half second,
// for bodies that were dynamic then: cm, p50 and p99); in all: geometry_bytes_per_impact (journal event
// messages sent to one client / impacts), the placement bytes against the previous protocol's (32-byte
// float records of every dynamic body, every time) in the same run, converge_ms (partition end → the last of
// the clients it cut off to have confirmed a frame at most 12 frames behind the host; each client's first
// such moment counts, since with loss some client's reliable acks are usually held up behind a lost one, and
// all at once may take long), late_join_ms, snapshot_bytes. With --out, one row is added to DIR/netplay.csv
// and DIR/netplay.png is drawn again.
//
// With --client-shots R each client asks the host for R shots a second at objects it sees; the host checks
// them (NetHost::setShotHandler) and fires those it accepts. With --shots-per-second 0 as well, the host is a
// headless authoritative server whose world changes only through its clients' checked shots.
#include "Subcommand.hpp"

#if defined(RUBBLE_HAVE_BULLET) && defined(RUBBLE_HAVE_ENET)

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "BenchUtil.hpp"
#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/enet/NetClient.hpp"
#include "rubble/enet/NetHost.hpp"
#include "rubble/enet/UdpRelay.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/SceneLoader.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Args {
    std::string file;
    double seconds = 60;
    int clients = 2;
    double shotsPerSecond = 10;
    double clientShots = 0; // shots per second each client asks the host for
    double shootFor = 0;    // client: seconds it shoots for
    int workers = -1;
    std::uint64_t seed = 1;
    double lateJoin = 1.0 / 3;
    bool json = false;
    double delayMs = 0, jitterMs = 0, loss = 0, burst = 1;
    double partitionAt = -1, partitionS = 0;
    rubble::net::PlacementBudget budget;
    double placementHz = 10;    // placements publishes a second
    std::string out;            // folder for netplay.csv and netplay.png ("" = none)
    int port = 0;               // client: the host's port
    std::string samples;        // client: where it writes its placement samples
    bool noBase = false;        // clients do not load the scene first (the snapshot brings every object)
    std::string replay;         // client: folder where it keeps the game when the host stops
    int resyncFrames = 60;      // clients: frames behind after an outage that ask for a resync (0: never)
    bool snapshotCache = false; // the host keeps objects compressed one by one (NetHost::setSnapshotCache)
};

// Frames between placement samples, and how far behind its latest sync a client shows placements.
constexpr long kSampleEvery = 30;
constexpr long kViewLag = 6;
// A client that keeps two placement periods in hand: a lost placements datagram is bridged by interpolation.
constexpr long kSafeViewLag = 12;

// A placement sample of a client: (frame, object, position).
struct Sample {
    std::uint32_t frame, object;
    float x, y, z;
    std::uint32_t lag; // kViewLag or kSafeViewLag
    float newest;      // the frame of the latest placement the client has of it
};

double percentile(std::vector<double> v, double q) {
    if (v.empty())
        return -1;
    std::sort(v.begin(), v.end());
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - (q > 0 ? 1 : 0);
    return v[std::min(k, v.size() - 1)];
}

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

Child spawn(const Args& a, std::uint16_t port, const std::string& samples) {
    int fds[2];
    if (pipe(fds) != 0)
        return {};
    const pid_t pid = fork();
    if (pid == 0) {
        dup2(fds[1], STDOUT_FILENO);
        close(fds[0]);
        close(fds[1]);
        const std::string p = std::to_string(port), w = std::to_string(a.workers), s = std::to_string(a.seed),
                          t = std::to_string(a.seconds + 60), shoot = std::to_string(a.clientShots),
                          until = std::to_string(a.seconds), resync = std::to_string(a.resyncFrames);
        execl("/proc/self/exe", "rubble-bench", "netplay-client", "--port", p.c_str(), "--workers", w.c_str(),
              "--seed", s.c_str(), "--seconds", t.c_str(), "--samples", samples.c_str(), "--shoot",
              shoot.c_str(), "--shoot-for", until.c_str(), "--scene", a.noBase ? "" : a.file.c_str(),
              "--resync-frames", resync.c_str(), static_cast<char*>(nullptr));
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

// The link of a client spawned `at` seconds into the run: the partition window is in run time.
rubble::net::LinkProfile linkProfile(const Args& a, double at) {
    rubble::net::LinkProfile p;
    p.delayMs = a.delayMs;
    p.jitterMs = a.jitterMs;
    p.loss = a.loss;
    p.burstLength = a.burst;
    if (a.partitionAt >= 0 && a.partitionS > 0 && a.partitionAt + a.partitionS > at) {
        p.partitionStartS = std::max(0.0, a.partitionAt - at);
        p.partitionS = a.partitionAt + a.partitionS - at - p.partitionStartS;
    }
    return p;
}

// Appends a row to DIR/netplay.csv (keeping the rows there) and draws DIR/netplay.png from all of them.
void writeResults(const std::string& dir, const std::vector<std::string>& header,
                  const std::vector<std::string>& row) {
    namespace fs = std::filesystem;
    rubble::bench::Table t;
    t.header = header;
    std::ifstream in(fs::path(dir) / "netplay.csv");
    std::string line;
    std::size_t columns = 0; // of the file's header: a prefix of this one (its rows get empty cells), or 0
    bool first = true;
    while (std::getline(in, line)) {
        if (first) { // an older header that is not a prefix of this one: its rows are dropped
            first = false;
            std::string h;
            for (std::size_t i = 0; i < header.size(); ++i) {
                h += (i ? "," : "") + header[i];
                if (line == h)
                    columns = i + 1;
            }
            if (columns == 0)
                break;
            continue;
        }
        std::vector<std::string> cells;
        std::string cell;
        for (std::istringstream ls(line); std::getline(ls, cell, ',');)
            cells.push_back(cell);
        if (!line.empty() && line.back() == ',')
            cells.emplace_back();
        if (cells.size() == columns) {
            cells.resize(header.size());
            t.rows.push_back(cells);
        }
    }
    t.rows.push_back(row);
    if (!rubble::bench::writeCsv(fs::path(dir) / "netplay.csv", t))
        return;
    std::string data;
    for (std::size_t i = 0; i < t.rows.size(); ++i) // index, label, kbps mean, kbps p99, error p99
        data += std::to_string(i) + " " + t.rows[i][1] + "c/" + t.rows[i][4] + "ms/" + t.rows[i][6] + " " +
                t.rows[i][11] + " " + t.rows[i][12] + " " + t.rows[i][17] + "\n";
    rubble::bench::plotPng(dir, "netplay", data,
                           "set title 'Netplay through the relay: kbps per client (clients/delay/loss)'\n"
                           "set style data histogram\nset style fill solid 0.6\nset yrange [0:*]\n"
                           "set ylabel 'kbps'\n"
                           "plot $DATA u 3:xtic(2) t 'mean', '' u 4 t 'p99 second', 150 w l t '150 kbps'");
}

// Loads the scene's objects into a runtime (host) the same way as into a client's world (its base).
bool loadObjects(const std::string& file, rubble::DestructionRuntime& runtime) {
    rubble::Result<rubble::SceneConfig> scene = rubble::parseSceneConfig(file);
    if (!scene) {
        std::cerr << "rubble-bench netplay: " << scene.error().message << "\n";
        return false;
    }
    rubble::SceneLoadOptions lo;
    lo.loadVehicle = false;
    (void)rubble::loadScene(*scene, runtime, lo);
    return true;
}

int runHost(const Args& a) {
    using namespace rubble;
    const DestructionRuntime::Config rc = runtimeConfig(a);
    bullet::PhysicsWorld physics;
    bullet::BulletBinding binding(physics);
    DestructionRuntime runtime(binding, rc);
    if (!loadObjects(a.file, runtime))
        return 2;
    auto server = net::NetHost::listen(runtime, rc.world, "127.0.0.1", 0, a.clients);
    if (!server) {
        std::cerr << "rubble-bench netplay: " << server.error().message << "\n";
        return 1;
    }
    net::NetHost& host = **server;
    host.setPlacementSource([&] { return runtime.placements(); });
    const long placementEvery = std::max(1L, std::lround(60.0 / a.placementHz)); // frames between publishes
    net::PlacementBudget budget = a.budget; // per publish: the same bytes per second at any rate
    budget.mean = budget.mean * static_cast<std::size_t>(placementEvery) / 6;
    budget.peak = budget.peak * static_cast<std::size_t>(placementEvery) / 6;
    host.setPlacementBudget(budget);
    host.setSnapshotCache(a.snapshotCache);
    const std::string tmp =
        (std::filesystem::temp_directory_path() / ("rubble-netplay-" + std::to_string(getpid()) + "-"))
            .string();
    std::vector<Child> children;
    std::vector<std::unique_ptr<net::UdpRelay>> relays;
    std::vector<std::vector<double>> kbps, kbpsUp; // per client, per second
    std::vector<std::vector<double>> secondEnds;   // per client: when each of those seconds ended (run s)
    std::vector<double> spawned;                   // per client: when it was started (run s)
    const auto start = Clock::now();
    const auto launch = [&] {
        const double at = std::chrono::duration<double>(Clock::now() - start).count();
        const net::LinkProfile link = linkProfile(a, at);
        auto relay = net::UdpRelay::start(host.port(), link, link, mixSeed(a.seed, 100 + children.size()));
        if (!relay) {
            std::cerr << "rubble-bench netplay: " << relay.error().message << "\n";
            return;
        }
        children.push_back(spawn(a, (*relay)->port(), tmp + std::to_string(children.size())));
        relays.push_back(std::move(*relay));
        kbps.emplace_back();
        kbpsUp.emplace_back();
        secondEnds.emplace_back();
        spawned.push_back(at);
    };
    for (int i = 0; i + 1 < a.clients; ++i)
        launch();
    Rng rng(mixSeed(a.seed, 0x4E7));
    const long frames = std::max(1L, std::lround(a.seconds * 60));
    const long lateFrame = a.clients > 0 ? std::lround(static_cast<double>(frames) * a.lateJoin) : -1;
    const rubble::bench::CpuMeter cpu; // the clients are other processes: "other" includes them
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / 60));
    std::map<std::uint64_t, std::map<ObjectId, Vec3>> truth; // frame → dynamic bodies' positions
    std::vector<long long> lastDown, lastUp;
    auto lastSecond = Clock::now();
    const auto partitionEnd = start + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(a.partitionAt + a.partitionS));
    double convergeMs = -1;
    long long partitioned = -1;    // clients joined when the partition ended
    std::vector<double> recovered; // per one of those: ms after the partition until it was within 12 frames
    long shots = 0, f = 0;
    std::vector<net::ShotRequest> requested; // clients' shots that passed the host's checks
    host.setShotHandler([&](const net::ShotRequest& r) { requested.push_back(r); });
    auto frame = [&](bool firing) {
        for (auto due = start + period * f; Clock::now() < due;) // the host serves the network meanwhile
            host.service(
                static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(due - Clock::now()).count()));
        const long due = static_cast<long>(static_cast<double>(f) * a.shotsPerSecond / 60.0);
        for (; firing && shots < due; ++shots)
            fire(runtime, rng);
        for (const net::ShotRequest& r : requested)
            runtime.fireProjectile(r.origin, r.velocity, 2, 0.25);
        requested.clear();
        runtime.stepFrame();
        host.publish();
        const std::uint64_t now = runtime.world().frame();
        if (f % placementEvery == 0 || now % kSampleEvery == 0) {
            const std::vector<ObjectPlacement> placements = runtime.placements();
            if (f % placementEvery == 0)
                host.publishPlacements(placements);
            if (now % kSampleEvery == 0)
                for (const ObjectPlacement& p : placements)
                    if (p.motion == BodyMotionState::Dynamic)
                        truth[now][p.object] = p.objectToWorld.translation;
        }
        host.service(0);
        if (Clock::now() - lastSecond >= std::chrono::seconds(1)) { // each client's link, per second
            const double dt = std::chrono::duration<double>(Clock::now() - lastSecond).count();
            lastSecond = Clock::now();
            lastDown.resize(relays.size(), 0);
            lastUp.resize(relays.size(), 0);
            for (std::size_t i = 0; i < relays.size(); ++i) {
                const long long down = relays[i]->down().bytesSent, up = relays[i]->up().bytesSent;
                kbps[i].push_back(static_cast<double>(down - lastDown[i]) * 8 / 1000 / dt);
                kbpsUp[i].push_back(static_cast<double>(up - lastUp[i]) * 8 / 1000 / dt);
                secondEnds[i].push_back(std::chrono::duration<double>(lastSecond - start).count());
                lastDown[i] = down;
                lastUp[i] = up;
            }
        }
        if (a.partitionS > 0 && convergeMs < 0 && Clock::now() >= partitionEnd) {
            if (partitioned < 0) // the clients that lived through it (a later joiner has nothing to recover)
                partitioned = host.stats().joins;
            const std::vector<std::uint64_t> confirmed = host.confirmedFrames(); // in join order
            const auto n = std::min<std::size_t>(confirmed.size(), static_cast<std::size_t>(partitioned));
            recovered.resize(n, -1);
            const double ms = std::chrono::duration<double, std::milli>(Clock::now() - partitionEnd).count();
            for (std::size_t i = 0; i < n; ++i) // the first time each one confirmed a frame within 12 of now
                if (recovered[i] < 0 && confirmed[i] + 12 >= now)
                    recovered[i] = ms;
            if (n > 0 && std::all_of(recovered.begin(), recovered.end(), [](double r) { return r >= 0; }))
                convergeMs = *std::max_element(recovered.begin(), recovered.end());
        }
        ++f;
    };
    net::HostStats beforeLate;     // the host's totals when the late client started
    std::size_t objectsAtLate = 0; // the world's objects then
    for (; f < frames;) {
        if (f == lateFrame) {
            beforeLate = host.stats();
            objectsAtLate = runtime.world().objects().size();
            launch();
        }
        frame(true);
    }
    for (int i = 0; i < 600 && runtime.world().jobsInFlight() > 0; ++i)
        frame(false);
    // Every client confirms the last sync (or 10 s pass).
    const std::uint64_t lastFrame = runtime.world().frame();
    for (const auto t0 = Clock::now(); Clock::now() - t0 < std::chrono::seconds(10);) {
        const std::vector<std::uint64_t> confirmed = host.confirmedFrames();
        if (confirmed.size() == children.size() &&
            std::all_of(confirmed.begin(), confirmed.end(), [&](std::uint64_t c) { return c >= lastFrame; }))
            break;
        host.service(5);
    }
    const net::HostStats hs = host.stats();
    const double runSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    const std::uint64_t hostHash = runtime.world().geometryHash(), hostFrame = runtime.world().frame();
    std::vector<std::string> unequal; // clients whose final hash is not the host's, and why
    host.close(5000);                 // the clients hear that the host stops, report and exit
    server->reset();
    nlohmann::json clients = nlohmann::json::array();
    long long mismatched = hs.mismatchedHashes;
    double lateJoinMs = -1;
    bool allConverged = true;
    std::vector<double> allErrors, allSafeErrors, means, p99s;
    std::map<long, std::vector<double>> allAhead; // lag → errors of samples past the newest placement
    for (std::size_t c = 0; c < children.size(); ++c) {
        Child& child = children[c];
        const std::string out = readAll(child.out);
        int status = 0;
        for (int i = 0; i < 1500 && waitpid(child.pid, &status, WNOHANG) == 0; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (waitpid(child.pid, &status, WNOHANG) == 0) {
            kill(child.pid, SIGKILL);
            waitpid(child.pid, &status, 0);
        }
        nlohmann::json report = nlohmann::json::parse(out, nullptr, false);
        nlohmann::json j;
        if (report.is_discarded() || !report.is_object()) {
            j = {{"error", "no report"}, {"output", out}};
            allConverged = false;
            unequal.push_back("client " + std::to_string(c) + " gave no report");
        } else {
            mismatched += report.value("mismatched_hashes", 0LL);
            lateJoinMs = report.value("join_ms", -1.0);
            const bool equal = report.value("geometry_hash", std::string()) == std::to_string(hostHash);
            allConverged = allConverged && equal;
            j = report;
            if (!equal) // what differed: where it stopped, and why
                unequal.push_back("client " + std::to_string(c) + " ended at frame " +
                                  std::to_string(report.value("frame", 0ULL)) + " of the host's " +
                                  std::to_string(hostFrame) + " (" + report.value("ending", std::string()) +
                                  "; " + std::to_string(report.value("syncs", 0LL)) + " syncs, " +
                                  std::to_string(report.value("mismatched_hashes", 0LL)) + " mismatched, " +
                                  std::to_string(report.value("resyncs", 0LL)) + " resyncs)");
        }
        // Placement error against the host, for bodies dynamic at the sampled frame.
        std::map<std::uint32_t, std::vector<double>> errorsAt; // lag → errors
        std::map<std::uint32_t, std::vector<double>> aheadAt;  // of those: the view past the newest placement
        nlohmann::json worst = nlohmann::json::array();        // samples off by more than 50 cm
        long long missing = 0;
        {
            const std::string path = tmp + std::to_string(c);
            std::ifstream in(path, std::ios::binary);
            std::map<std::uint32_t, std::map<std::uint64_t, std::map<ObjectId, Vec3>>> seen;
            std::map<std::pair<std::uint64_t, ObjectId>, float> newest;
            for (Sample smp{}; in.read(reinterpret_cast<char*>(&smp), sizeof smp);) {
                seen[smp.lag][smp.frame][smp.object] = Vec3{smp.x, smp.y, smp.z};
                newest[{smp.frame, smp.object}] = smp.newest;
            }
            std::filesystem::remove(path);
            for (const auto& [lag, sampled] : seen)
                for (const auto& [fr, bodies] : sampled) {
                    const auto t = truth.find(fr);
                    if (t == truth.end())
                        continue;
                    for (const auto& [id, at] : t->second) {
                        const auto v = bodies.find(id);
                        if (v == bodies.end()) {
                            missing += lag == kViewLag;
                            continue;
                        }
                        errorsAt[lag].push_back(length(v->second - at) * 100);
                        if (newest[{fr, id}] < static_cast<float>(fr))
                            aheadAt[lag].push_back(errorsAt[lag].back());
                        if (errorsAt[lag].back() > 50)
                            worst.push_back({{"cm", errorsAt[lag].back()},
                                             {"object", id},
                                             {"frame", fr},
                                             {"lag", lag},
                                             {"newest", newest[{fr, id}]}});
                    }
                }
        }
        const std::vector<double>& errors = errorsAt[kViewLag];
        allErrors.insert(allErrors.end(), errors.begin(), errors.end());
        allSafeErrors.insert(allSafeErrors.end(), errorsAt[kSafeViewLag].begin(),
                             errorsAt[kSafeViewLag].end());
        // In play: the seconds that began 0.25 s (a round trip, and the host's slack before it sends a chunk
        // again) or more after its snapshot arrived, by the client's clock (the same monotonic clock); the
        // join's burst, with the chunks sent again meanwhile, is reported apart.
        const double joined = report.is_object() && report.value("joined_s", -1.0) >= 0
                                  ? report.value("joined_s", -1.0) -
                                        std::chrono::duration<double>(start.time_since_epoch()).count() + 0.25
                                  : spawned[c] + (report.is_object() ? report.value("scene_load_ms", 0.0) +
                                                                           report.value("join_ms", 0.0)
                                                                     : 0.0) /
                                                     1000;
        std::vector<double> play, joining;
        for (std::size_t k = 0; k < kbps[c].size(); ++k)
            (secondEnds[c][k] - 1 > joined ? play : joining).push_back(kbps[c][k]);
        double sum = 0;
        for (double k : play)
            sum += k;
        const double mean = play.empty() ? 0 : sum / static_cast<double>(play.size());
        means.push_back(mean);
        p99s.push_back(percentile(play, 0.99));
        j["kbps_mean"] = mean;
        j["kbps_p99"] = percentile(play, 0.99);
        j["kbps_join_max"] = percentile(joining, 1.0);
        j["kbps_up_p99"] = percentile(kbpsUp[c], 0.99);
        j["mismatched_hashes"] = report.is_object() ? report.value("mismatched_hashes", 0LL) : -1;
        j["placement_error_cm"] = {{"p50", percentile(errors, 0.5)},
                                   {"p99", percentile(errors, 0.99)},
                                   {"samples", errors.size()},
                                   {"missing", missing}};
        j["placement_errors_over_50cm"] = worst;
        if (a.partitionS > 0 && report.is_object() && report.contains("outage")) {
            const double end = std::chrono::duration<double>(partitionEnd.time_since_epoch()).count();
            const nlohmann::json& o = report["outage"];
            const auto after = [&](const char* k) {
                return o.value(k, -1.0) < 0 ? -1.0 : (o.value(k, -1.0) - end) * 1000;
            };
            j["outage"] = {{"heard_again_ms", after("heard_again_s")},
                           {"caught_up_ms", after("caught_up_s")},
                           {"service_ms", o.value("service_ms", 0.0)}};
        }
        j["placement_error_cm_lag12"] = {{"p50", percentile(errorsAt[kSafeViewLag], 0.5)},
                                         {"p99", percentile(errorsAt[kSafeViewLag], 0.99)}};
        for (const long lag : {kViewLag, kSafeViewLag}) { // samples shown past the body's newest placement
            const std::vector<double>& ahead = aheadAt[static_cast<std::uint32_t>(lag)];
            j["placement_error_cm_past_newest"]["lag" + std::to_string(lag)] = {
                {"samples", ahead.size()}, {"p50", percentile(ahead, 0.5)}, {"p99", percentile(ahead, 0.99)}};
            allAhead[lag].insert(allAhead[lag].end(), ahead.begin(), ahead.end());
        }
        nlohmann::json seconds = nlohmann::json::array(); // kbps per second, with when each second ended
        for (std::size_t k = 0; k < kbps[c].size(); ++k)
            seconds.push_back({std::round(secondEnds[c][k] * 10) / 10, std::round(kbps[c][k])});
        j["kbps_seconds"] = seconds;
        j["link"] = {{"down_lost", relays[c]->down().lost},
                     {"down_partition_drops", relays[c]->down().partitionDrops},
                     {"up_lost", relays[c]->up().lost}};
        clients.push_back(j);
    }
    const double impacts =
        static_cast<double>(hs.impactEvents) / std::max(1, static_cast<int>(children.size()));
    const double perClientEventBytes =
        static_cast<double>(hs.eventBytes) / std::max<std::size_t>(1, children.size());
    const double perClient = static_cast<double>(std::max<std::size_t>(1, children.size()));
    nlohmann::json r;
    r["scene"] = a.file;
    r["seconds"] = runSeconds;
    r["link"] = {{"delay_ms", a.delayMs}, {"jitter_ms", a.jitterMs},       {"loss", a.loss},
                 {"burst", a.burst},      {"partition_at", a.partitionAt}, {"partition_s", a.partitionS}};
    r["placement_budget"] = {{"mean", a.budget.mean}, {"peak", a.budget.peak}, {"reserve", a.budget.reserve}};
    r["placement_hz"] = a.placementHz;
    r["placements_deferred_per_publish"] =
        static_cast<double>(hs.placementsDeferred) / perClient / (runSeconds * 60.0 / placementEvery);
    r["placement_publishes_full_share"] =
        static_cast<double>(hs.placementPublishesFull) / perClient / (runSeconds * 60.0 / placementEvery);
    r["impacts"] = runtime.counters().impacts;
    r["fractures"] = runtime.counters().fractures;
    r["geometry_bytes_per_impact"] = impacts > 0 ? perClientEventBytes / impacts : 0;
    r["transform_bytes_per_s"] = static_cast<double>(hs.placementBytes) / perClient / runSeconds;
    r["legacy_transform_bytes_per_s"] = static_cast<double>(hs.legacyPlacementBytes) / perClient / runSeconds;
    r["placement_bytes_ratio_vs_legacy"] =
        hs.legacyPlacementBytes > 0
            ? static_cast<double>(hs.placementBytes) / static_cast<double>(hs.legacyPlacementBytes)
            : 0;
    r["mismatched_hashes"] = mismatched;
    r["client_shots_accepted"] = hs.shotsAccepted;
    r["client_shots_refused"] = hs.shotsRefused;
    r["late_join_ms"] = lateJoinMs;
    r["snapshot_bytes"] = hs.snapshotBytes / std::max<long long>(1, hs.joins);
    r["snapshot_raw_bytes"] = hs.snapshotRawBytes / std::max<long long>(1, hs.joins);
    r["snapshot_objects_by_reference"] = hs.snapshotObjectsByReference / std::max<long long>(1, hs.joins);
    r["clients_load_scene"] = !a.noBase;
    r["snapshot_builds"] = hs.snapshotBuilds;
    r["snapshot_build_ms"] =
        hs.snapshotBuildMs / static_cast<double>(std::max<long long>(1, hs.snapshotBuilds));
    const auto perBuild = [&hs](double ms) {
        return ms / static_cast<double>(std::max<long long>(1, hs.snapshotBuilds));
    };
    r["snapshot_capture_ms"] = perBuild(hs.snapshotCaptureMs);
    r["snapshot_encode_ms"] = perBuild(hs.snapshotEncodeMs);
    r["snapshot_compress_ms"] = perBuild(hs.snapshotCompressMs);
    if (lateFrame >= 0 && !clients.empty()) { // the late client's join, stage by stage
        const nlohmann::json& late = clients.back();
        r["late_join"] = {{"world_objects", objectsAtLate},
                          {"builds", hs.snapshotBuilds - beforeLate.snapshotBuilds},
                          {"build_ms", hs.snapshotBuildMs - beforeLate.snapshotBuildMs},
                          {"capture_ms", hs.snapshotCaptureMs - beforeLate.snapshotCaptureMs},
                          {"encode_ms", hs.snapshotEncodeMs - beforeLate.snapshotEncodeMs},
                          {"compress_ms", hs.snapshotCompressMs - beforeLate.snapshotCompressMs},
                          {"transfer_ms", hs.snapshotTransferMs - beforeLate.snapshotTransferMs},
                          {"bytes", hs.snapshotBytes - beforeLate.snapshotBytes},
                          {"join_ms", late.value("join_ms", -1.0)},
                          {"hello_ms", late.value("hello_ms", -1.0)},
                          {"connect_ms", late.value("connect_ms", -1.0)},
                          {"first_chunk_ms", late.value("first_chunk_ms", -1.0)},
                          {"snapshot_decode_ms", late.value("snapshot_decode_ms", -1.0)},
                          {"snapshot_load_ms", late.value("snapshot_load_ms", -1.0)}};
    }
    r["snapshot_chunks_sent"] = hs.snapshotChunksSent;
    r["snapshot_cache"] = a.snapshotCache;
    r["snapshot_objects_packed"] = hs.snapshotObjectsPacked;
    r["objects_warmed"] = hs.objectsWarmed;
    r["snapshot_transfer_ms"] = hs.snapshotTransferMs / static_cast<double>(std::max<long long>(1, hs.joins));
    r["resync_frames"] = a.resyncFrames;
    r["resyncs"] = hs.resyncs;
    r["resync_bytes"] = hs.resyncBytes / std::max<long long>(1, hs.resyncs);
    r["resync_objects_sent"] = hs.resyncObjectsSent / std::max<long long>(1, hs.resyncs);
    r["resync_transfer_ms"] = hs.resyncTransferMs / static_cast<double>(std::max<long long>(1, hs.resyncs));
    r["final_hashes_equal"] = allConverged;
    r["unequal_clients"] = unequal;
    r["converge_ms"] = convergeMs;
    r["kbps_mean"] = means.empty() ? 0 : *std::max_element(means.begin(), means.end());
    r["kbps_p99"] = p99s.empty() ? 0 : *std::max_element(p99s.begin(), p99s.end());
    r["placement_error_cm"] = {{"p50", percentile(allErrors, 0.5)}, {"p99", percentile(allErrors, 0.99)}};
    r["placement_error_cm_lag12"] = {{"p50", percentile(allSafeErrors, 0.5)},
                                     {"p99", percentile(allSafeErrors, 0.99)}};
    for (const auto& [lag, ahead] : allAhead)
        r["placement_error_cm_past_newest"]["lag" + std::to_string(lag)] = {
            {"samples", ahead.size()}, {"p50", percentile(ahead, 0.5)}, {"p99", percentile(ahead, 0.99)}};
    r["host_geometry_hash"] = std::to_string(hostHash);
    r["clients"] = clients;
    const auto use = cpu.read();
    r["cpu_cores"] = {{"own", use.own}, {"other", use.other}};
    if (!a.out.empty()) {
        namespace b = rubble::bench;
        std::streambuf* const stdout = std::cout.rdbuf(std::cerr.rdbuf()); // stdout is for --json
        struct Restore {
            std::streambuf* buf;
            ~Restore() { std::cout.rdbuf(buf); }
        } restore{stdout};
        writeResults(a.out,
                     {"scene",
                      "clients",
                      "seconds",
                      "shots_per_second",
                      "delay_ms",
                      "jitter_ms",
                      "loss",
                      "burst",
                      "partition_s",
                      "impacts",
                      "geometry_bytes_per_impact",
                      "kbps_mean",
                      "kbps_p99",
                      "legacy_placement_kbps",
                      "placement_kbps",
                      "placement_ratio_vs_legacy",
                      "error_p50_cm",
                      "error_p99_cm",
                      "error_p99_cm_lag12",
                      "mismatched_hashes",
                      "final_hashes_equal",
                      "converge_ms",
                      "late_join_ms",
                      "snapshot_bytes",
                      "other_cpu_cores",
                      "resync_frames",
                      "resyncs",
                      "resync_bytes",
                      "snapshot_build_ms"},
                     {std::filesystem::path(a.file).filename().string(),
                      std::to_string(a.clients),
                      b::fixed(runSeconds, 1),
                      b::fixed(a.shotsPerSecond, 1),
                      b::fixed(a.delayMs, 0),
                      b::fixed(a.jitterMs, 0),
                      b::fixed(a.loss, 3),
                      b::fixed(a.burst, 1),
                      b::fixed(a.partitionS, 1),
                      std::to_string(runtime.counters().impacts),
                      b::fixed(r["geometry_bytes_per_impact"].get<double>(), 1),
                      b::fixed(r["kbps_mean"].get<double>(), 1),
                      b::fixed(r["kbps_p99"].get<double>(), 1),
                      b::fixed(r["legacy_transform_bytes_per_s"].get<double>() * 8 / 1000, 1),
                      b::fixed(r["transform_bytes_per_s"].get<double>() * 8 / 1000, 1),
                      b::fixed(r["placement_bytes_ratio_vs_legacy"].get<double>(), 3),
                      b::fixed(percentile(allErrors, 0.5), 2),
                      b::fixed(percentile(allErrors, 0.99), 2),
                      b::fixed(percentile(allSafeErrors, 0.99), 2),
                      std::to_string(mismatched),
                      allConverged ? "1" : "0",
                      b::fixed(convergeMs, 0),
                      b::fixed(lateJoinMs, 0),
                      std::to_string(r["snapshot_bytes"].get<long long>()),
                      b::fixed(use.other, 2),
                      std::to_string(a.resyncFrames),
                      std::to_string(hs.resyncs),
                      std::to_string(r["resync_bytes"].get<long long>()),
                      b::fixed(r["snapshot_build_ms"].get<double>(), 0)});
    }
    if (a.json) {
        std::cout << r.dump() << "\n";
    } else {
        std::cout << "netplay " << a.file << ": " << r["impacts"] << " impacts, "
                  << r["geometry_bytes_per_impact"] << " geometry bytes/impact, " << r["kbps_mean"]
                  << " kbps mean (worst client), " << r["kbps_p99"] << " kbps p99 second, placements "
                  << r["placement_bytes_ratio_vs_legacy"] << " of the float records, error p99 "
                  << r["placement_error_cm"]["p99"] << " cm, " << mismatched
                  << " mismatched hashes, late join " << lateJoinMs << " ms, converge " << convergeMs
                  << " ms, final hashes equal: " << (allConverged ? "yes" : "NO") << "\n";
    }
    for (const std::string& u : unequal)
        std::cerr << "rubble-bench netplay: final hash differs: " << u << "\n";
    const bool shotsTaken = a.clientShots <= 0 || hs.shotsAccepted > 0;
    return mismatched == 0 && allConverged && shotsTaken && !children.empty() ? 0 : 1;
}

int runClient(const Args& a) {
    using namespace rubble;
    const DestructionRuntime::Config rc = runtimeConfig(a);
    DestructionWorld world(rc.world);
    double baseMs = 0;
    if (!a.file.empty()) { // the scene, as the host loaded it: the host sends these objects by id
        const auto t0 = Clock::now();
        bullet::PhysicsWorld physics;
        bullet::BulletBinding binding(physics);
        DestructionRuntime loader(binding, rc);
        if (!loadObjects(a.file, loader))
            return 2;
        if (Status st = restoreSnapshot(world, takeSnapshot(loader.world())); !st) {
            std::cout << nlohmann::json{{"error", st.message()}}.dump() << "\n";
            return 1;
        }
        baseMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    }
    const auto connectAt = Clock::now();
    auto client = net::NetClient::connect(world, rc.world, "127.0.0.1", static_cast<std::uint16_t>(a.port));
    if (!client) {
        std::cout << nlohmann::json{{"error", client.error().message}}.dump() << "\n";
        return 1;
    }
    (*client)->setResyncFrames(a.resyncFrames);
    (*client)->setKeepReplay(!a.replay.empty());
    Rng aim(mixSeed(a.seed, static_cast<std::uint64_t>(getpid())));
    long long shotsSent = 0;
    const auto shootAt = [&](double view) { // a shot from 30 m at a random destructible object it can see
        std::vector<ObjectId> targets;
        for (ObjectId id : world.objects())
            if (world.object(id)->destructible && (*client)->placement(id, view))
                targets.push_back(id);
        if (targets.empty())
            return;
        const ObjectId id = targets[static_cast<std::size_t>(aim.below(targets.size()))];
        const Vec3 at = (*client)->placement(id, view)->apply(world.object(id)->mesh.bounds().center());
        const double phi = aim.uniform(0, 2 * 3.14159265358979);
        const Vec3 dir = normalized(Vec3{std::cos(phi), 0.3, std::sin(phi)});
        if ((*client)->shoot(at + dir * 30.0, dir * -120.0))
            ++shotsSent;
    };
    const auto started = Clock::now();
    std::ofstream samples;
    if (!a.samples.empty())
        samples.open(a.samples, std::ios::binary);
    std::string ending = "time limit";
    bool hostStopped = false;
    std::uint64_t lastFrame = 0;
    std::vector<double> behind; // at each sample: newest placement frame received − the world's frame
    // After an outage (nothing heard for 1 s): when the host was heard again, when the world caught up with
    // the placements received (within 12 frames), and the time spent in service() in between.
    Clock::time_point quietSince = Clock::now(), heardAgain{}, caughtUp{};
    long long lastHeard = 0;
    double busyMs = 0;
    const auto monotonic = [](Clock::time_point t) { // monotonic seconds, comparable across processes
        return t.time_since_epoch().count() == 0
                   ? -1.0
                   : std::chrono::duration<double>(t.time_since_epoch()).count();
    };
    for (const auto t0 = Clock::now(); Clock::now() - t0 < std::chrono::duration<double>(a.seconds);) {
        const auto serviced = Clock::now();
        if (Status s = (*client)->service(5); !s) {
            ending = s.message();
            hostStopped = s.error().code == ErrorCode::IoError;
            break;
        }
        const auto now = Clock::now();
        const long long heard = (*client)->stats().placements + (*client)->stats().syncs;
        if (heard != lastHeard) {
            if (heardAgain.time_since_epoch().count() == 0 && lastHeard != 0 &&
                now - quietSince > std::chrono::seconds(1))
                heardAgain = now;
            quietSince = now;
            lastHeard = heard;
        }
        if (heardAgain.time_since_epoch().count() != 0 && caughtUp.time_since_epoch().count() == 0) {
            busyMs += std::chrono::duration<double, std::milli>(now - serviced).count();
            double newest = 0;
            for (ObjectId id : world.objects())
                newest = std::max(newest, (*client)->placementFrame(id).value_or(0));
            if (static_cast<double>((*client)->stats().frame) + 12 >= newest)
                caughtUp = now;
        }
        // What it would show now: one placement period behind its latest sync, every half second.
        const std::uint64_t frame = (*client)->stats().frame;
        for (const long lag : {kViewLag, kSafeViewLag}) {
            if (frame == lastFrame || !samples || frame < static_cast<std::uint64_t>(lag) ||
                (frame - static_cast<std::uint64_t>(lag)) % kSampleEvery != 0)
                continue;
            const double view = static_cast<double>(frame - static_cast<std::uint64_t>(lag));
            double newest = static_cast<double>(frame);
            for (ObjectId id : world.objects())
                newest = std::max(newest, (*client)->placementFrame(id).value_or(0));
            if (lag == kViewLag)
                behind.push_back(newest - static_cast<double>(frame));
            for (ObjectId id : world.objects()) {
                const std::optional<double> latest = (*client)->placementFrame(id);
                if (!latest || *latest < view - 120)
                    continue; // at rest for two seconds or more: not a moving body
                const Frame at = *(*client)->placement(id, view);
                const Sample smp{static_cast<std::uint32_t>(view),     id,
                                 static_cast<float>(at.translation.x), static_cast<float>(at.translation.y),
                                 static_cast<float>(at.translation.z), static_cast<std::uint32_t>(lag),
                                 static_cast<float>(*latest)};
                samples.write(reinterpret_cast<const char*>(&smp), sizeof smp);
            }
        }
        lastFrame = frame;
        const double since = std::chrono::duration<double>(Clock::now() - started).count();
        if (a.clientShots > 0 && (*client)->stats().joined && since < a.shootFor &&
            static_cast<double>(shotsSent) < since * a.clientShots)
            shootAt(static_cast<double>(frame));
    }
    std::string replay; // the game so far, kept when the host stopped
    if (hostStopped && !a.replay.empty()) {
        const std::filesystem::path dir = a.replay;
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        const Status saved = (*client)->writeReplay(dir / "game.rbsn", dir / "game.rbj");
        replay = saved ? (dir / "game.rbsn").string() + " + " + (dir / "game.rbj").string() : saved.message();
        std::cerr << "netplay-client: " << ending << "; "
                  << (saved ? "the game so far is in " : "cannot keep the game: ") << replay << "\n";
    }
    const net::ClientStats& st = (*client)->stats();
    nlohmann::json j{{"joined", st.joined},
                     {"join_ms", st.joinMs},
                     {"joined_s", st.joined ? monotonic(connectAt) + st.joinMs / 1000 : -1.0},
                     {"scene_load_ms", baseMs},
                     {"hello_ms", st.helloMs},
                     {"connect_ms", st.connectMs},
                     {"first_chunk_ms", st.firstChunkMs},
                     {"snapshot_decode_ms", st.snapshotDecodeMs},
                     {"snapshot_load_ms", st.snapshotLoadMs},
                     {"events", st.events},
                     {"syncs", st.syncs},
                     {"mismatched_hashes", st.mismatchedHashes},
                     {"frame", st.frame},
                     {"geometry_hash", std::to_string(world.geometryHash())},
                     {"placements", st.placements},
                     {"placement_bytes", st.placementBytes},
                     {"shots_sent", shotsSent},
                     {"resyncs", st.resyncs},
                     {"first_mismatch", st.firstMismatch},
                     {"resync_load_ms", st.resyncLoadMs},
                     {"outage",
                      {{"heard_again_s", monotonic(heardAgain)},
                       {"caught_up_s", monotonic(caughtUp)},
                       {"service_ms", busyMs}}},
                     {"sync_behind_placements_frames",
                      {{"p50", percentile(behind, 0.5)}, {"p99", percentile(behind, 0.99)}}},
                     {"ending", ending},
                     {"replay", replay}};
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
         app.add_option("--clients", a->clients, "client processes")->check(CLI::Range(1, 16));
         app.add_option("--shots-per-second", a->shotsPerSecond, "projectiles per second the host fires");
         app.add_option(
                "--client-shots", a->clientShots,
                "shots per second each client asks for (the host checks them, fires those it accepts)")
             ->check(CLI::Range(0.0, 100.0));
         app.add_option("--workers", a->workers, "fracture workers of host and clients (-1 automatic)");
         app.add_option("--seed", a->seed, "world and firing seed");
         app.add_option("--late-join", a->lateJoin, "the last client joins at this fraction of the run")
             ->check(CLI::Range(0.0, 1.0));
         app.add_option("--delay-ms", a->delayMs, "one-way delay of each client's link (each way)")
             ->check(CLI::Range(0.0, 5000.0));
         app.add_option("--jitter-ms", a->jitterMs, "standard deviation of that delay")
             ->check(CLI::Range(0.0, 1000.0));
         app.add_option("--loss", a->loss, "fraction of datagrams lost (each way)")
             ->check(CLI::Range(0.0, 0.9));
         app.add_option("--burst", a->burst, "mean datagrams per loss burst (1: independent losses)")
             ->check(CLI::Range(1.0, 100.0));
         app.add_option("--partition-at", a->partitionAt, "seconds into the run when every link goes dead");
         app.add_option("--partition-s", a->partitionS, "how long the links stay dead")
             ->check(CLI::Range(0.0, 60.0));
         app.add_option("--placement-budget", a->budget.mean,
                        "placement bytes per client per 10 Hz publish, mean (scaled at other rates)")
             ->check(CLI::Range(100, 1000000));
         app.add_option("--placement-hz", a->placementHz,
                        "placements publishes a second (the budget's bytes per publish scale with it)")
             ->check(CLI::Range(1.0, 60.0));
         app.add_option("--placement-peak", a->budget.peak, "placement bytes per client in one publish")
             ->check(CLI::Range(100, 1000000));
         app.add_option("--placement-reserve", a->budget.reserve, "placement bytes a client may save up")
             ->check(CLI::Range(100, 10000000));
         app.add_option("--out", a->out, "folder: add a row to netplay.csv, draw netplay.png");
         app.add_flag("--no-base", a->noBase,
                      "clients do not load the scene first: the snapshot brings every object");
         app.add_flag("--snapshot-cache", a->snapshotCache,
                      "the host keeps each object compressed on its own and packs new ones ahead");
         app.add_option("--resync-frames", a->resyncFrames,
                        "frames behind the host after an outage at which a client asks for a resync (0: "
                        "never; it cuts the backlog itself)")
             ->check(CLI::Range(0, 100000));
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
         app.add_option("--samples", a->samples, "file for its placement samples");
         app.add_option("--shoot", a->clientShots, "shots per second it asks the host for");
         app.add_option("--shoot-for", a->shootFor, "seconds it shoots for");
         app.add_option("--scene", a->file, "world.cfg it loads before joining (\"\": none)");
         app.add_option("--replay", a->replay,
                        "folder where it keeps the game (snapshot + journal) when the host stops");
         app.add_option("--resync-frames", a->resyncFrames, "frames behind after an outage for a resync");
         return [a] { return runClient(*a); };
     }}};

} // namespace

#endif
