// rubble-demo: fly, shoot, watch things break. GLFW + OpenGL 3.3 (libepoxy) + Dear ImGui; headless via EGL.
#include <epoxy/gl.h>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "Audio.hpp"
#include "Autopilot.hpp"
#include "DynamicResolution.hpp"
#include "Game.hpp"
#include "GlContext.hpp"
#include "JoinSession.hpp"
#include "Panel.hpp"
#include "RasterThreads.hpp"
#include "RenderBench.hpp"
#include "Renderer.hpp"
#include "RubblePaths.hpp"
#include "RunReport.hpp"
#include "ScaledTarget.hpp"
#include "Weapons.hpp"
#include "rubble/rubble.hpp"

namespace {

using Clock = std::chrono::steady_clock;

/// Built-in scene used when the default world.cfg is missing (models missing → box stand-ins).
const char* kFallbackScene =
    "sky_top.png;sky_bottom.png;sky_left.png;sky_right.png;sky_front.png;sky_back.png\n"
    ";ground.png;0;-15;0;1000;10;1000;0\n"
    "vehicle.obj;;0;20;0;1;1;1;100\n"
    "tower.obj;;-15;20;-150;8;30;8;0\n"
    "tower.obj;;25;10;-210;10;20;10;0\n"
    "tower.obj;;-45;25;-260;7;35;7;0\n"
    "tower.obj;;60;5;-300;12;15;12;0\n"
    "tower.obj;;0;-5;-120;4;5;4;300\n";

/// The fracture workers' default niceness: above llvmpipe's rasteriser threads (docs/rendering.md).
constexpr int kWorkerNice = -5;
/// How long a frame waits, before drawing, for a fracture job in flight (ms).
constexpr double kAdoptWaitMs = 0;

struct Options {
    std::string scene;
    bool debug = false;
    double autopilot = 0;
    double screenshotEvery = 0;
    std::string out;
    bool stats = false;
    int statsEvery = 30;
    int width = 1280;
    int height = 720;
    bool headless = false;
    bool window = false;
    int workers = -1;
    double blastCutVolume = demo::GameSettings{}.blastCutVolume;               // --blast-cut-volume
    double collisionFractureRate = demo::GameSettings{}.collisionFractureRate; // --collision-fracture-rate
    int blastMaxCuts = demo::GameSettings{}.blastMaxCuts;                      // --blast-max-cuts
    std::string pattern = "adaptive";
    int cells = 6;
    bool noPanel = false;
    bool deterministic = false;
    bool noShadows = false;
    bool bilinear = false;
    bool showcase = false;
    std::vector<std::string> hits;     // "X,Y,Z,IMPULSE": impacts in the first frame
    bool holdFire = false;             // the autopilot flies without shooting
    std::string camera;                // "EX,EY,EZ,TX,TY,TZ": a fixed showcase camera
    std::string charge;                // "X,Y,Z,RADIUS,IMPULSE,SECONDS": one demolition charge
    std::string record;                // journal file written at exit
    std::string replay;                // journal file replayed on the loaded scene instead of playing
    int host = 0;                      // port to host loopback multiplayer on
    double hostWait = 0;               // game seconds at which the host holds until a client joins
    std::string join;                  // HOST:PORT of a host to follow
    double joinFire = 0;               // with --join: seconds between automatic shots
    bool structure = true;             // the stress solver (with bearings)
    bool rough = true;                 // rough cuts by material (docs/roughness.md)
    bool bonds = false;                // draw its bonds by stress
    std::string quality = "auto";      // auto (from GL_RENDERER), software or gpu
    float targetFps = 60;              // dynamic resolution holds this rate (software quality)
    float minScale = -1;               // smallest internal resolution scale (-1: the quality's)
    std::string renderBench;           // "N,N,...": the render bench's resting piece counts
    int benchFrames = 60;              // measured frames per render bench row
    bool json = false;                 // the render bench prints JSON
    int rasterNice = 0;                // niceness of llvmpipe's rasteriser threads (0: unchanged)
    int rasterThreads = -1;            // LP_NUM_THREADS for llvmpipe (-1: unchanged)
    int workerNice = kWorkerNice;      // niceness of the fracture workers (0: unchanged)
    double fireRate = 0;               // cannon shots per game second at objects and large pieces (0: none)
    bool adoptReady = false;           // the autopilot adopts results when ready, not a fixed 2 frames later
    double adoptWaitMs = kAdoptWaitMs; // before drawing, wait this long for a fracture job in flight
    int rasterYield = 0;               // llvmpipe's niceness while fracture jobs run (0: unchanged)
    double demolish = 0;               // seconds between demolition charges on standing targets (0: none)
    int maxAwake = 0;                  // awake debris budget (0: the game's default)
    double lightPerAwake = -1;         // light pieces per budgeted awake body (< 0: the game's default)
    bool mute = false;                 // no sound
    std::string audioWav;              // the run's sound captured to this WAV file (no device)
    bool structureFlag = false;        // --structure given (its bonds are drawn)
};

/// Sounds at once, at most.
constexpr int kVoices = 24;

struct App {
    Options opt;
    std::unique_ptr<demo::GlContext> gl;
    demo::RenderQuality quality;
    demo::Renderer renderer;
    demo::ScaledTarget sceneTarget;
    demo::Game game;
    demo::Panel panel;
    demo::GameSettings pending;
    rubble::SceneConfig scene;
    std::string sceneName;
    std::vector<std::filesystem::path> scenes; // what N cycles through: the demolition, the thesis's scenes
    std::size_t sceneIndex = 0;
    bool nextScene = false;                              // N pressed
    std::vector<std::pair<demo::V3, float>> hits;        // --hit: (point, impulse), after the first load
    std::optional<std::pair<demo::V3, demo::V3>> camera; // --camera: (eye, target), after every load
    std::optional<std::array<float, 6>> charge;          // --charge: x, y, z, radius, impulse, seconds
    bool paused = false;
    bool quit = false;
    bool screenshotRequested = false;
    int screenshots = 0;
    bool imguiGlfw = false;
};

App* gApp = nullptr;

void keyCallback(GLFWwindow* w, int key, int, int action, int) {
    if (action != GLFW_PRESS || !gApp)
        return;
    if (ImGui::GetCurrentContext() && ImGui::GetIO().WantTextInput)
        return;
    App& a = *gApp;
    switch (key) {
    case GLFW_KEY_ESCAPE:
        a.quit = true;
        glfwSetWindowShouldClose(w, GLFW_TRUE);
        break;
    case GLFW_KEY_P:
        a.paused = !a.paused;
        break;
    case GLFW_KEY_SPACE:
        if (a.paused)
            a.paused = false;
        break;
    case GLFW_KEY_F1:
        a.panel.toggle();
        break;
    case GLFW_KEY_H:
        a.panel.help = !a.panel.help;
        break;
    case GLFW_KEY_R:
        a.game.respawn();
        break;
    case GLFW_KEY_1:
    case GLFW_KEY_2:
    case GLFW_KEY_3:
        a.game.setWeapon(static_cast<demo::Weapon>(demo::weaponForDigit(key - GLFW_KEY_0)));
        break;
    case GLFW_KEY_N:
        a.nextScene = true;
        break;
    case GLFW_KEY_L:
        a.game.settings().autoLevel = !a.game.settings().autoLevel;
        a.pending.autoLevel = a.game.settings().autoLevel;
        break;
    case GLFW_KEY_F2:
        a.screenshotRequested = true;
        break;
    case GLFW_KEY_F5: // quick save / quick load: a snapshot of the destroyed world and its bodies
    case GLFW_KEY_F9: {
        const std::string path = (a.opt.out.empty() ? std::string(".") : a.opt.out) + "/quicksave.rsnap";
        std::string message;
        const bool save = key == GLFW_KEY_F5;
        const bool ok =
            save ? a.game.saveSnapshot(path, message) : a.game.loadSnapshot(path, a.renderer, message);
        std::printf("%s: %s %s (%s)\n", save ? "F5" : "F9",
                    ok ? (save ? "saved" : "loaded") : (save ? "cannot save" : "cannot load"), path.c_str(),
                    message.c_str());
        std::fflush(stdout);
        break;
    }
    case GLFW_KEY_F3: {
        auto& s = a.game.settings();
        const bool on = !(s.debugShapes || s.debugAabbs || s.debugImpacts);
        s.debugShapes = s.debugAabbs = s.debugImpacts = on;
        break;
    }
    default:
        break;
    }
}

demo::ControlInput readKeys(GLFWwindow* w, bool& spaceHeld) {
    demo::ControlInput in;
    auto down = [w](int k) { return glfwGetKey(w, k) == GLFW_PRESS; };
    in.pitch = (down(GLFW_KEY_W) ? 1.0f : 0.0f) - (down(GLFW_KEY_S) ? 1.0f : 0.0f);
    in.roll = (down(GLFW_KEY_A) ? 1.0f : 0.0f) - (down(GLFW_KEY_D) ? 1.0f : 0.0f);
    in.yaw = (down(GLFW_KEY_Q) ? 1.0f : 0.0f) - (down(GLFW_KEY_E) ? 1.0f : 0.0f);
    in.throttle = (down(GLFW_KEY_Z) ? 1.0f : 0.0f) - (down(GLFW_KEY_X) ? 1.0f : 0.0f);
    spaceHeld = down(GLFW_KEY_SPACE);
    in.fire = spaceHeld;
    return in;
}

/// A fresh renderer with the scene's sky and interior texture.
bool prepareRenderer(App& a, std::string& error) {
    std::vector<std::string> warnings;
    a.renderer.shutdown();
    a.renderer = demo::Renderer();
    std::string rerr;
    if (!a.renderer.init(a.quality, rerr)) {
        error = "renderer: " + rerr;
        return false;
    }
    // Interior material of cut faces: interior.png next to the scene, in ../textures, or in assets/textures.
    for (const auto& candidate :
         {a.scene.baseDir / "interior.png", a.scene.baseDir / "../textures/interior.png",
          std::filesystem::path(rubble::generated::sourceDir) / "assets/textures/interior.png"})
        if (std::filesystem::exists(candidate) && a.renderer.setInteriorTexture(candidate))
            break;
    bool skyOk = true;
    for (const auto& p : a.scene.skyboxPaths)
        skyOk = skyOk && !p.empty() && std::filesystem::exists(p);
    if (skyOk)
        a.renderer.setSkybox(a.scene.skyboxPaths, warnings);
    for (const auto& w : warnings)
        std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (!skyOk)
        std::fprintf(stderr, "warning: skybox images missing; drawing the procedural sky\n");
    return true;
}

bool loadScene(App& a, std::string& error) {
    if (!prepareRenderer(a, error))
        return false;
    std::vector<std::string> warnings;
    if (!a.game.load(a.scene, a.renderer, a.pending, warnings, error))
        return false;
    for (const auto& w : warnings)
        std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (a.camera)
        a.game.setShowcaseView(a.camera->first, a.camera->second);
    return true;
}

/// Exactly n comma-separated numbers from text into out.
bool parseNumbers(const std::string& text, std::size_t n, float* out) {
    const char* p = text.c_str();
    for (std::size_t i = 0; i < n; ++i) {
        char* end = nullptr;
        out[i] = std::strtof(p, &end);
        if (end == p || *end != (i + 1 < n ? ',' : '\0'))
            return false;
        p = end + 1;
    }
    return true;
}

/// How this run draws: decided by setUp from the options and the display.
struct RunMode {
    bool headless = false;    // EGL offscreen
    bool autopilot = false;   // --autopilot
    std::string rendererName; // GL_RENDERER
    int reniced = 0;          // llvmpipe threads reniced
};

/// Parses the command line into o: -1 to go on, else the exit code (--help, a bad option).
int parseOptions(int argc, char** argv, Options& o) {
    CLI::App cli{"rubble-demo: fly a vehicle through a world.cfg scene and shoot destructible objects.\n"
                 "Keys: W/S pitch, A/D roll, Q/E yaw, Z/X speed, Space fire/unpause, P pause, Esc quit,\n"
                 "F1 panel, F2 screenshot, F3 debug overlay, F5/F9 quick save/load, H key help."};
    cli.add_option(
        "--scene", o.scene,
        "world.cfg scene (thesis format); default assets/scenes/demolition.cfg (N cycles to the "
        "thesis's scenes in ../shared/seed/media or RUBBLE_SEED_MEDIA, and assets/scenes/world.cfg)");
    cli.add_flag("-d,--debug", o.debug, "draw collision shapes, AABBs and impact points");
    cli.add_option("--autopilot", o.autopilot, "fly and shoot by script for SECONDS (fixed 1/60 s steps)");
    cli.add_option("--screenshot-every", o.screenshotEvery,
                   "write a PNG every S simulated seconds (needs --out)");
    cli.add_option("--out", o.out, "output folder for screenshots and the timing report");
    cli.add_flag("--stats", o.stats, "print a stats line to stdout every --stats-every frames");
    cli.add_option("--stats-every", o.statsEvery, "frames between stats lines (default 30)");
    cli.add_option("--width", o.width, "framebuffer width");
    cli.add_option("--height", o.height, "framebuffer height");
    cli.add_flag("--headless", o.headless, "render offscreen with EGL (default when DISPLAY is unset)");
    cli.add_flag("--window", o.window, "open a window even for --autopilot");
    cli.add_option("--workers", o.workers, "fracture worker threads (-1 automatic)");
    cli.add_option("--blast-cut-volume", o.blastCutVolume,
                   "blasts throw moving pieces below this volume (m^3) instead of cutting them (0: cut all)")
        ->check(CLI::NonNegativeNumber);
    cli.add_option("--blast-max-cuts", o.blastMaxCuts,
                   "moving bodies a blast may cut, nearest first; the rest are thrown (0: any)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cli.add_option("--collision-fracture-rate", o.collisionFractureRate,
                   "fractures a second that collisions (not shots) may start, the strongest first (0: any)")
        ->check(CLI::NonNegativeNumber);
    cli.add_option("--pattern", o.pattern,
                   "fracture pattern: adaptive (weak hits chip, strong hits shatter), single or shatter")
        ->check(CLI::IsMember({"adaptive", "single", "shatter"}));
    cli.add_option("--cells", o.cells, "cells K of the shatter pattern");
    cli.add_flag(
        "--no-panel", o.noPanel,
        "hide the panel's compact HUD line too (F1 shows the full panel; by default it starts collapsed)");
    cli.add_flag("--deterministic", o.deterministic, "adopt fractures a fixed number of frames after impact");
    cli.add_flag("--no-shadows", o.noShadows, "disable shadow mapping");
    cli.add_flag("--showcase", o.showcase, "the camera frames the scene's objects from a fixed point");
    cli.add_option(
        "--hit", o.hits,
        "X,Y,Z,IMPULSE: an impact at that world point (N s) in the first frame, on the objects whose "
        "bounds reach it (repeatable; e.g. pictures of fracture patterns with --hold-fire)");
    cli.add_flag("--hold-fire", o.holdFire, "the autopilot flies without shooting");
    cli.add_option(
           "--demolish", o.demolish,
           "every SECONDS of game time a demolition charge blasts the next standing object or large "
           "piece until nothing stands (with --showcase and demolition_block.cfg: the block comes down)")
        ->check(CLI::Range(0.05, 60.0));
    cli.add_option(
           "--max-awake", o.maxAwake,
           "awake debris budget: beyond it settled pieces freeze, then the smallest moving ones retire "
           "to particles (default 400)")
        ->check(CLI::Range(50, 20000));
    cli.add_option("--light-per-awake", o.lightPerAwake,
                   "moving pieces over the awake budget collide with static bodies only, up to this many per "
                   "budgeted awake body, before any retire (default 4; 0: they retire)")
        ->check(CLI::Range(0.0, 100.0));
    cli.add_flag("--mute", o.mute, "no sound (headless runs have none: no audio device is opened)");
    cli.add_option("--audio-wav", o.audioWav,
                   "FILE: the run's sound, mixed in step with game time, written as a WAV file (no device)");
    cli.add_option(
        "--camera", o.camera,
        "EX,EY,EZ,TX,TY,TZ: a fixed camera at EX,EY,EZ looking at TX,TY,TZ (also in the --join window)");
    cli.add_option("--charge", o.charge,
                   "X,Y,Z,RADIUS,IMPULSE,SECONDS: one demolition charge blasts the objects within RADIUS of "
                   "that point at that game time (IMPULSE N s at its centre, 40 % at its edge)");
    cli.add_flag("--bilinear", o.bilinear, "software quality: bilinear textures instead of nearest texels");
    cli.add_option("--record", o.record,
                   "write the destruction journal (every impact and removal, 48 bytes each) to FILE at exit");
    cli.add_option(
        "--replay", o.replay,
        "replay the journal FILE on the loaded scene, print its geometry hash and exit (a bug report's "
        "fractures, reproduced; run with the recording's options)");
    cli.add_option(
           "--host", o.host,
           "host loopback multiplayer on 127.0.0.1:PORT (needs --deterministic); clients: rubble-bench "
           "netplay-client --port PORT")
        ->check(CLI::Range(1, 65535));
    cli.add_option("--host-wait", o.hostWait,
                   "with --host: hold the game at SECONDS of game time until a client has joined (at most "
                   "120 s), so that it joins late and still sees fractures live")
        ->needs("--host")
        ->check(CLI::PositiveNumber);
    cli.add_option(
           "--join", o.join,
           "follow a --host game at HOST:PORT (loopback) in a window: the client cuts the pieces from "
           "the host's journal and draws them at the host's placements; A/D orbit, W/S zoom, Space asks "
           "the host for a shot")
        ->excludes("--host");
    cli.add_option("--join-fire", o.joinFire,
                   "with --join: ask the host for a shot at an object every SECONDS (the host checks it)")
        ->needs("--join")
        ->check(CLI::PositiveNumber);
    cli.add_option(
           "--quality", o.quality,
           "renderer quality: auto (software GL gets the software level), software (per-vertex light, "
           "no shadows, nearest texels, fewer dust particles) or gpu (per-pixel light, shadows)")
        ->check(CLI::IsMember({"auto", "software", "gpu"}));
    cli.add_option("--target-fps", o.targetFps, "frame rate dynamic resolution holds (default 60)")
        ->check(CLI::Range(5.0, 1000.0));
    cli.add_option(
           "--min-scale", o.minScale,
           "smallest internal resolution scale per axis dynamic resolution may use to hold --target-fps "
           "(default 1 = off; 0.667 keeps 1280x720 at 1080p)")
        ->check(CLI::Range(0.25, 1.0));
    cli.add_flag("--structure,!--no-structure", o.structure,
                 "stress solver (default on): bonds between static parts carry their load, objects rest on "
                 "each other as bearings; --structure also draws the bonds by stress");
    cli.add_flag("--rough,!--flat", o.rough,
                 "rough cut surfaces by material (default on: concrete, brick and stone break rough; a "
                 "world.cfg roughness field overrides); --flat cuts the thesis's flat Voronoi planes");
    cli.add_flag("--bonds", o.bonds, "draw the structure's bonds by stress");
    cli.add_option(
        "--render-bench", o.renderBench,
        "N,N,...: render fields of N resting fractured pieces (and 64 moving ones) offscreen at "
        "--width x --height and print the CPU per frame and draw calls of each (rubble-bench render "
        "runs this), then exit");
    cli.add_option("--bench-frames", o.benchFrames, "measured frames per --render-bench row (default 60)")
        ->check(CLI::Range(1, 100000));
    cli.add_flag("--json", o.json, "--render-bench prints a JSON list of rows");
    cli.add_option(
           "--raster-nice", o.rasterNice,
           "niceness of llvmpipe's rasteriser threads (default 0: unchanged): above 0, fracture workers run "
           "before them (on a machine shared with other work they also lose to it; docs/rendering.md)")
        ->check(CLI::Range(0, 19));
    cli.add_option("--raster-threads", o.rasterThreads,
                   "llvmpipe's rasteriser threads (sets LP_NUM_THREADS before the GL context; 0: the main "
                   "thread rasterises; default: Mesa's, one per core)")
        ->check(CLI::Range(0, 64));
    cli.add_option("--raster-yield", o.rasterYield,
                   "niceness of llvmpipe's rasteriser threads while a fracture job is queued or running, "
                   "back to --raster-nice when none is (default 0: unchanged), so that the workers get the "
                   "cores; report.json's threads.yielded_frames counts the frames drawn so")
        ->check(CLI::Range(0, 19));
    cli.add_option("--worker-nice", o.workerNice,
                   "niceness of the fracture worker threads (default " + std::to_string(kWorkerNice) +
                       "; below 0 they run before software GL's rasteriser threads, which needs "
                       "CAP_SYS_NICE; report.json says what the system granted)")
        ->check(CLI::Range(-20, 19));
    cli.add_option("--fire-rate", o.fireRate,
                   "cannon shots per game second at the objects and pieces of 1 m^3 or more, round robin, "
                   "from 40 m on the camera's side (a latency run's steady fractures; also with --hold-fire)")
        ->check(CLI::Range(0.0, 60.0));
    cli.add_option(
           "--adopt-wait", o.adoptWaitMs,
           "ms a frame waits before drawing for a fracture job in flight to finish, so that its pieces "
           "appear in this frame rather than the next (default " +
               CLI::detail::to_string(kAdoptWaitMs) + "; not in deterministic runs)")
        ->check(CLI::Range(0.0, 100.0));
    cli.add_flag("--adopt-ready", o.adoptReady,
                 "with --autopilot: adopt fracture results as soon as their job finished, right before "
                 "drawing (as play does), not exactly 2 frames after the impact; impact -> adopted latency "
                 "then measures the workers, but runs are no longer deterministic");
    CLI11_PARSE(cli, argc, argv);
    o.structureFlag = cli.count("--structure") > 0;
    return -1;
}

/// --render-bench: the renderer alone on fields of resting pieces.
int renderBench(const Options& o) {
    demo::RenderBenchOptions b;
    std::string message;
    if (!demo::parsePieceCounts(o.renderBench, b.pieces, message)) {
        std::fprintf(stderr, "error: %s\n", message.c_str());
        return 2;
    }
    b.width = o.width;
    b.height = o.height;
    b.frames = o.benchFrames;
    b.json = o.json;
    b.quality = o.quality;
    b.out = o.out;
    return demo::runRenderBench(b);
}

/// --hit and --camera parsed, the display mode, the scene, the settings and the GL context: -1 to go on, else
/// the exit code.
int setUp(App& app, RunMode& mode) {
    const Options& o = app.opt;
    for (const std::string& text : o.hits) {
        float v[4];
        if (!parseNumbers(text, 4, v) || !(v[3] > 0)) {
            std::fprintf(stderr, "error: --hit %s: expected X,Y,Z,IMPULSE with IMPULSE > 0\n", text.c_str());
            return 2;
        }
        app.hits.push_back({demo::V3{v[0], v[1], v[2]}, v[3]});
    }
    if (!o.camera.empty()) {
        float v[6];
        if (!parseNumbers(o.camera, 6, v)) {
            std::fprintf(stderr, "error: --camera %s: expected EX,EY,EZ,TX,TY,TZ\n", o.camera.c_str());
            return 2;
        }
        app.camera = {demo::V3{v[0], v[1], v[2]}, demo::V3{v[3], v[4], v[5]}};
    }
    if (!o.charge.empty()) {
        std::array<float, 6> v{};
        if (!parseNumbers(o.charge, 6, v.data()) || !(v[3] > 0) || !(v[4] > 0) || !(v[5] >= 0)) {
            std::fprintf(stderr,
                         "error: --charge %s: expected X,Y,Z,RADIUS,IMPULSE,SECONDS (RADIUS, IMPULSE > 0)\n",
                         o.charge.c_str());
            return 2;
        }
        app.charge = v;
    }

    const bool haveDisplay = std::getenv("DISPLAY") && *std::getenv("DISPLAY");
    const bool autopilot = o.autopilot > 0;
    bool headless = o.headless || !haveDisplay;
    if (o.window)
        headless = false;
    if (autopilot && !o.window && !haveDisplay)
        headless = true;
    if (!autopilot && headless && !o.headless) {
        std::fprintf(stderr,
                     "rubble-demo: no DISPLAY. Run with --autopilot SECONDS --out DIR for a headless run, "
                     "or under xvfb-run.\n");
        return 2;
    }

    // Scene.
    const std::filesystem::path assets =
        std::filesystem::path(rubble::generated::sourceDir) / "assets/scenes";
    std::filesystem::path scenePath =
        o.scene.empty() ? assets / "demolition.cfg" : std::filesystem::path(o.scene);
    if (o.scene.empty() && !std::filesystem::exists(scenePath))
        scenePath = assets / "world.cfg";
    if (o.scene.empty() && !std::filesystem::exists(scenePath)) {
        std::fprintf(stderr, "warning: %s not found; using the built-in fallback scene\n",
                     scenePath.string().c_str());
        auto r = rubble::parseSceneConfigText(kFallbackScene, "builtin.cfg",
                                              std::filesystem::path(rubble::generated::sourceDir) / "assets");
        if (!r) {
            std::fprintf(stderr, "error: %s\n", r.error().message.c_str());
            return 1;
        }
        app.scene = r.value();
        app.sceneName = "built-in scene";
    } else {
        auto r = rubble::parseSceneConfig(scenePath);
        if (!r) {
            std::fprintf(stderr, "error: %s\n", r.error().message.c_str());
            return 1;
        }
        app.scene = r.value();
        app.sceneName = scenePath.filename().string();
        app.scenes.push_back(scenePath);
    }
    { // N cycles: this scene, the demolition, the thesis's scenes (when its media folder is there), world.cfg
        const char* seedEnv = std::getenv("RUBBLE_SEED_MEDIA");
        const std::filesystem::path seed =
            seedEnv ? std::filesystem::path(seedEnv)
                    : std::filesystem::path(rubble::generated::sourceDir) / "../shared/seed/media";
        for (const auto& p : {assets / "demolition.cfg", seed / "world.cfg", seed / "performance_test.cfg",
                              seed / "cube_test.cfg", assets / "world.cfg"}) {
            std::error_code ec;
            if (!std::filesystem::exists(p, ec))
                continue;
            bool known = false;
            for (const auto& q : app.scenes)
                known = known || std::filesystem::equivalent(p, q, ec);
            if (!known)
                app.scenes.push_back(p);
        }
    }

    app.pending.workers = o.workers;
    app.pending.workerNice = o.workerNice;
    app.pending.blastCutVolume = o.blastCutVolume;
    app.pending.collisionFractureRate = o.collisionFractureRate;
    app.pending.blastMaxCuts = o.blastMaxCuts;
    app.pending.deterministic = o.deterministic || (autopilot && !o.adoptReady);
    app.pending.fracture.pattern = o.pattern == "shatter"  ? rubble::CellPattern::Shatter
                                   : o.pattern == "single" ? rubble::CellPattern::SingleCell
                                                           : rubble::CellPattern::Adaptive;
    app.pending.fracture.cells = o.cells;
    app.pending.fracture.sizeLaw = demo::demoSizeLaw(app.pending.fracture.pattern);
    app.pending.fracture.uvScale = 0.25;
    app.pending.debugShapes = app.pending.debugAabbs = app.pending.debugImpacts = o.debug;
    app.pending.structure = o.structure;
    app.pending.roughCuts = o.rough;
    app.pending.debugBonds = o.structure && (o.bonds || o.structureFlag);
    app.pending.showcase = o.showcase || !o.camera.empty();
    if (o.maxAwake > 0)
        app.pending.maxAwake = o.maxAwake;
    if (o.lightPerAwake >= 0)
        app.pending.lightPerAwake = o.lightPerAwake;

    std::string error;
    if (o.rasterThreads >= 0) // Mesa reads it when the context's screen is made
        setenv("LP_NUM_THREADS", std::to_string(o.rasterThreads).c_str(), 1);
    app.gl = demo::GlContext::create(o.width, o.height, headless, error);
    if (!app.gl) {
        std::fprintf(stderr, "error: %s\n", error.c_str());
        return 1;
    }
    const std::string rendererName = app.gl->renderer();
    app.quality = demo::RenderQuality::forRenderer(o.quality == "gpu" ? std::string("gpu") : rendererName);
    if (o.quality == "software" && !app.quality.software)
        app.quality = demo::RenderQuality::forRenderer("llvmpipe");
    if (o.minScale > 0)
        app.quality.minScale = o.minScale;
    if (o.bilinear)
        app.quality.nearestTexels = false;
    app.pending.shadows = !o.noShadows && app.quality.shadows;
    const int reniced = o.rasterNice > 0 ? demo::setRasterizerNice(o.rasterNice) : 0;
    mode.headless = headless;
    mode.autopilot = autopilot;
    mode.rendererName = rendererName;
    mode.reniced = reniced;
    return -1;
}

/// --join: a follower with no game of its own draws the host's world.
int joinMode(App& app) {
    const Options& o = app.opt;
    std::string error;
    demo::JoinOptions j{{},           0,          o.workers, o.out, o.screenshotEvery, o.stats,
                        o.statsEvery, o.joinFire, app.camera};
    if (!demo::parseHostPort(o.join, j.address, j.port, error) || !prepareRenderer(app, error)) {
        std::fprintf(stderr, "error: %s\n", error.c_str());
        return 1;
    }
    app.renderer.shadows = app.pending.shadows;
    const int status = demo::runJoin(j, *app.gl, app.renderer, app.scene);
    app.renderer.shutdown();
    app.gl.reset();
    return status;
}

/// Loads the scene, applies --hit and starts --host: -1 to go on, else the exit code.
int startGame(App& app) {
    const Options& o = app.opt;
    std::string error;
    if (!loadScene(app, error)) {
        std::fprintf(stderr, "error: %s\n", error.c_str());
        return 1;
    }
    for (const auto& [at, impulse] : app.hits)
        if (!app.game.hitAt(at, impulse))
            std::fprintf(stderr, "warning: --hit %g,%g,%g reached no object\n", static_cast<double>(at.x),
                         static_cast<double>(at.y), static_cast<double>(at.z));

    if (o.host > 0) {
        std::string message;
        if (!app.game.host(static_cast<std::uint16_t>(o.host), message)) {
            std::fprintf(stderr, "error: cannot host on port %d: %s\n", o.host, message.c_str());
            return 1;
        }
        std::printf("host: listening on %s\n", message.c_str());
        std::fflush(stdout);
    }
    return -1;
}

/// --replay: the journal replayed on the loaded scene, its geometry hash printed.
int replayMode(App& app) {
    const Options& o = app.opt;
    std::uint64_t hash = 0;
    std::string message;
    const bool ok = app.game.replayJournal(o.replay, hash, message);
    if (ok)
        std::printf("replay: %s (%s), geometry hash %016llx\n", o.replay.c_str(), message.c_str(),
                    static_cast<unsigned long long>(hash));
    else
        std::fprintf(stderr, "error: cannot replay %s: %s\n", o.replay.c_str(), message.c_str());
    app.game.clear(app.renderer);
    app.renderer.shutdown();
    app.gl.reset();
    return ok ? 0 : 1;
}

/// Play (and host): the frame loop until quit or the end of the autopilot, then the report and the journal.
// Dear ImGui over the window (or offscreen), the keys bound; returns its IO.
ImGuiIO& startUi(App& app, bool autopilot) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui::GetStyle().WindowRounding = 6.0f;
    ImGui::GetStyle().FrameRounding = 3.0f;
    if (app.gl->window()) {
        glfwSwapInterval(autopilot ? 0 : 1); // play at the display's rate; scripted runs as fast as possible
        glfwSetWindowUserPointer(app.gl->window(), &app);
        glfwSetKeyCallback(app.gl->window(), keyCallback);
        ImGui_ImplGlfw_InitForOpenGL(app.gl->window(), true);
        app.imguiGlfw = true;
    }
    ImGui_ImplOpenGL3_Init("#version 330 core");
    app.panel.visible = !app.opt.noPanel;
    return io;
}

// The end of a run: the audio capture, report.json, the host's and the journal's summaries; then the UI, the
// game and the window closed. Returns the exit status.
int finishRun(App& app, demo::Audio& audio, demo::RunReport& report, const std::string& rendererName,
              int yieldedFrames) {
    const Options& o = app.opt;
    if (std::string message; !audio.finish(message)) {
        std::fprintf(stderr, "error: %s\n", message.c_str());
        return 1;
    }
    report.setAudio(audio.stats(), kVoices, audio.hasDevice());
    if (const demo::PriorityJobs* jobs = app.game.jobs())
        report.setThreads({jobs->workerCount(), jobs->nice(), jobs->raised(), jobs->refused(),
                           static_cast<int>(demo::rasterizerThreads().size()), !app.pending.deterministic,
                           o.adoptWaitMs, jobs->busyMs(), jobs->cpuMs(), yieldedFrames});
    report.setVisibleLatencies(app.game.visibleLatency().visibleMs());
    if (!o.out.empty()) {
        std::string summary;
        const auto outDir = std::filesystem::path(o.out);
        if (report.write(
                outDir, app.scene.baseDir.string() + "/" + app.sceneName,
                {rendererName, app.quality.name(), app.pending.shadows, app.gl->width(), app.gl->height()},
                app.game.latencies(), app.screenshots, summary)) {
            app.game.writeTimings((outDir / "latency.csv").string());
            (void)app.game.visibleLatency().writeCsv(outDir / "visible.csv");
            std::printf("report: %s\n", summary.c_str());
            std::printf("wrote %s/report.json, %s/frames.csv and %d screenshots\n", o.out.c_str(),
                        o.out.c_str(), app.screenshots);
        } else {
            std::fprintf(stderr, "error: cannot write the report into %s\n", o.out.c_str());
        }
    }
    int status = 0;
    app.game.finishHosting(); // the clients confirm the last sync before the connections close
    if (const rubble::net::HostStats* h = app.game.hostStats())
        std::printf("host: %lld clients joined, %lld syncs sent, %lld acknowledged, %lld mismatched hashes, "
                    "geometry hash %016llx\n",
                    h->joins, h->syncs, h->acks, h->mismatchedHashes,
                    static_cast<unsigned long long>(app.game.geometryHash()));
    if (!o.record.empty()) {
        std::string message;
        const std::uint64_t hash = app.game.finishRecording();
        if (app.game.writeJournal(o.record, app.scene.baseDir.string() + "/" + app.sceneName, message)) {
            std::printf("journal: %s (%s), geometry hash %016llx\n", o.record.c_str(), message.c_str(),
                        static_cast<unsigned long long>(hash));
        } else {
            std::fprintf(stderr, "error: cannot write the journal %s: %s\n", o.record.c_str(),
                         message.c_str());
            status = 1;
        }
    }
    std::fflush(stdout);

    ImGui_ImplOpenGL3_Shutdown();
    if (app.imguiGlfw)
        ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    app.game.clear(app.renderer);
    app.renderer.shutdown();
    app.sceneTarget.release();
    app.gl.reset();
    return status;
}

int frameLoop(App& app, const RunMode& mode) {
    const Options& o = app.opt;
    const bool headless = mode.headless;
    const bool autopilot = mode.autopilot;
    const std::string& rendererName = mode.rendererName;
    const int reniced = mode.reniced;
    std::string error;
    ImGuiIO& io = startUi(app, autopilot);

    if (!o.out.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(o.out, ec);
    }
    std::fprintf(stderr,
                 "rubble-demo: %s, %dx%d, %s, %s quality (shadows %s, %s lighting, internal scale >= %.2f), "
                 "fracture DestructionWorld + rubble_bullet, %d rasteriser threads at niceness %d\n",
                 headless ? "EGL offscreen" : "window", app.gl->width(), app.gl->height(),
                 rendererName.c_str(), app.quality.name(), app.pending.shadows ? "on" : "off",
                 app.quality.pixelLighting ? "per-pixel" : "per-vertex", app.quality.minScale, reniced,
                 o.rasterNice);
    demo::Audio audio({!headless, o.mute, o.audioWav, kVoices}); // silently no device when none opens
    demo::DynamicResolution resolution(1000.0f / o.targetFps, app.quality.minScale);
    demo::RasterYield rasterYield(o.rasterYield, o.rasterNice);
    float lastFrameMs = 0;

    demo::Autopilot pilot;
    demo::RunReport report;
    const float fixedDt = 1.0f / 60.0f;
    const long totalFrames = autopilot ? std::lround(o.autopilot * 60.0) : -1;
    const long shotEvery = o.screenshotEvery > 0 ? std::max(1L, std::lround(o.screenshotEvery * 60.0)) : 0;
    long renderFrame = 0;
    long nextDemolish = 60; // --demolish: game frame of the next charge (the first after a second)
    long nextShot = 60;     // --fire-rate: game frame of the next shell
    double accumulator = 0;
    auto last = Clock::now();

    while (!app.quit) {
        const auto frameStart = Clock::now();
        double realDt = std::chrono::duration<double>(frameStart - last).count();
        last = frameStart;
        if (app.gl->window()) {
            glfwPollEvents();
            if (glfwWindowShouldClose(app.gl->window()))
                app.quit = true;
        }

        // Simulation.
        const auto stepStart = Clock::now();
        demo::GameSettings& live = app.game.settings();
        if (o.hostWait > 0 &&
            static_cast<long>(app.game.counters().frame) == std::lround(o.hostWait * 60.0) &&
            !app.game.waitForClient(120.0)) {
            std::fprintf(stderr, "error: --host-wait: no client joined within 120 s\n");
            return 1;
        }
        if (o.demolish > 0 && !o.holdFire && static_cast<long>(app.game.counters().frame) >= nextDemolish) {
            app.game.blastNextTarget(); // --demolish: the next charge, on the next standing target
            nextDemolish = static_cast<long>(app.game.counters().frame) + std::lround(o.demolish * 60.0);
        }
        if (app.charge &&
            static_cast<long>(app.game.counters().frame) >= std::lround((*app.charge)[5] * 60.0)) {
            const auto& c = *app.charge; // --charge: once, at its game time
            app.game.blast(demo::V3{c[0], c[1], c[2]}, c[3], c[4], static_cast<int>(demo::Weapon::Charge));
            app.charge.reset();
        }
        if (o.fireRate > 0 && static_cast<long>(app.game.counters().frame) >= nextShot) {
            app.game.shootNextTarget(app.game.camera().eye); // --fire-rate: the next shell
            nextShot =
                static_cast<long>(app.game.counters().frame) + std::max(1L, std::lround(60.0 / o.fireRate));
        }
        if (autopilot) {
            demo::ControlInput in = pilot.update(app.game, fixedDt);
            in.fire = in.fire && !app.opt.holdFire;
            app.game.step(in, fixedDt, app.renderer);
        } else if (!app.paused) {
            bool space = false;
            demo::ControlInput in;
            if (app.gl->window() && !ImGui::GetIO().WantCaptureKeyboard)
                in = readKeys(app.gl->window(), space);
            accumulator += std::min(realDt, 0.1);
            int steps = 0;
            while (accumulator >= fixedDt && steps < 4) {
                app.game.step(in, fixedDt * live.timeScale, app.renderer);
                accumulator -= fixedDt;
                ++steps;
            }
            if (steps == 4)
                accumulator = 0;
        } else {
            accumulator = 0;
        }
        // Fracture results that finished during the steps are adopted now, before drawing, so that their
        // pieces appear in this frame rather than after the next step (no-op in deterministic mode, which the
        // autopilot uses; nothing changes while paused).
        if (!app.paused || autopilot)
            app.game.adoptReady(o.adoptWaitMs);
        rasterYield.update(app.game.counters().jobs > 0);
        const double stepMs = std::chrono::duration<double, std::milli>(Clock::now() - stepStart).count();
        { // Sound: heard from the camera, the capture in step with game time.
            const demo::M4 view = app.game.camera().view();
            audio.setListener(app.game.camera().eye, demo::V3{view.m[0], view.m[4], view.m[8]});
            audio.play(app.game.takeSounds());
            audio.advance(autopilot ? fixedDt : (app.paused ? 0.0 : std::min(realDt, 0.1)));
        }

        // Scene.
        const int w = app.gl->width(), h = app.gl->height();
        resolution.update(lastFrameMs);
        int iw = w, ih = h;
        resolution.size(w, h, iw, ih);
        const bool scaled = (iw != w || ih != h) && app.sceneTarget.reserve(w, h);
        if (!scaled)
            iw = w, ih = h;
        app.renderer.beginFrame();
        app.game.draw(app.renderer, autopilot ? fixedDt : static_cast<float>(std::min(realDt, 0.1)));
        demo::FrameView fv;
        fv.width = iw;
        fv.height = ih;
        fv.fbo = scaled ? app.sceneTarget.framebuffer() : app.gl->framebuffer();
        fv.eye = app.game.camera().eye;
        fv.view = app.game.camera().view();
        fv.proj = demo::perspective(1.05f, static_cast<float>(w) / static_cast<float>(std::max(h, 1)), 0.5f,
                                    3000.0f);
        demo::V3 vpos, vfwd, vup;
        app.game.vehicleFrame(vpos, vfwd, vup);
        fv.focus = vpos + vfwd * 60.0f;
        app.renderer.render(fv);
        if (scaled)
            app.sceneTarget.blitTo(app.gl->framebuffer(), iw, ih, w, h);

        // UI.
        io.DisplaySize = ImVec2(static_cast<float>(w), static_cast<float>(h));
        io.DeltaTime = autopilot || realDt <= 0 ? fixedDt : static_cast<float>(realDt);
        ImGui_ImplOpenGL3_NewFrame();
        if (app.imguiGlfw)
            ImGui_ImplGlfw_NewFrame();
        if (autopilot) {
            io.DeltaTime = fixedDt;
        }
        if (app.nextScene &&
            !app.scenes.empty()) { // N: the next scene; a scene that does not parse is skipped
            app.nextScene = false;
            app.sceneIndex = (app.sceneIndex + 1) % app.scenes.size();
            const auto& next = app.scenes[app.sceneIndex];
            if (auto r = rubble::parseSceneConfig(next); r) {
                app.scene = r.value();
                app.sceneName = next.filename().string();
                if (!loadScene(app, error)) {
                    std::fprintf(stderr, "error: %s\n", error.c_str());
                    break;
                }
                std::printf("scene: %s\n", next.string().c_str());
            } else {
                std::fprintf(stderr, "error: %s\n", r.error().message.c_str());
            }
            std::fflush(stdout);
        }
        app.panel.scaleToWindow(h);
        ImGui::NewFrame();
        app.panel.pushLatencies(app.game.takeNewLatencies());
        if (app.panel.draw(app.game, app.pending, app.paused, app.sceneName, rendererName,
                           app.renderer.drawCalls(), app.renderer.triangles())) {
            app.pending.timeScale = live.timeScale;
            app.pending.debugShapes = live.debugShapes;
            app.pending.debugAabbs = live.debugAabbs;
            app.pending.debugImpacts = live.debugImpacts;
            app.pending.shadows = live.shadows;
            if (!loadScene(app, error)) {
                std::fprintf(stderr, "error: %s\n", error.c_str());
                break;
            }
        }
        app.panel.drawHud(app.game, app.paused, w, h);
        ImGui::Render();
        glBindFramebuffer(GL_FRAMEBUFFER, app.gl->framebuffer());
        glViewport(0, 0, w, h);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

        ++renderFrame;
        const std::uint64_t simFrame = app.game.counters().frame;
        const bool lastFrame = autopilot && static_cast<long>(simFrame) >= totalFrames;
        const bool timedShot =
            shotEvery > 0 && (autopilot ? (static_cast<long>(simFrame) % shotEvery == 0 || lastFrame)
                                        : renderFrame % shotEvery == 0);
        double shotMs = 0;
        if ((timedShot || app.screenshotRequested) && !o.out.empty()) {
            const auto shotStart = Clock::now();
            std::string rgb;
            int sw = 0, sh = 0;
            app.gl->readPixels(rgb, sw, sh);
            char name[64];
            std::snprintf(name, sizeof name, "shot_%04d.png", ++app.screenshots);
            const auto path = std::filesystem::path(o.out) / name;
            if (demo::writePng(path, rgb, sw, sh))
                std::printf("screenshot %s frame=%llu\n", path.string().c_str(),
                            static_cast<unsigned long long>(simFrame));
            std::fflush(stdout);
            app.screenshotRequested = false;
            shotMs = std::chrono::duration<double, std::milli>(Clock::now() - shotStart).count();
        }
        app.gl->present();
        app.game.presented(); // fractures adopted before this frame are on screen now

        // Frame time without the PNG encoding of screenshots.
        const double frameMs =
            std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count() - shotMs;
        app.panel.pushFrameMs(static_cast<float>(frameMs));
        const demo::GameCounters& c = app.game.counters();
        lastFrameMs = static_cast<float>(frameMs);
        report.add({simFrame, static_cast<double>(simFrame) / 60.0, frameMs, stepMs, c,
                    app.renderer.drawCalls(), iw, ih});
        if (o.stats && renderFrame % std::max(1, o.statsEvery) == 0) {
            std::printf(
                "stats render=%ld frame=%llu paused=%d shots=%d impacts=%d fractures=%d bodies=%d pieces=%d "
                "awake=%d frozen=%d jobs=%d crashes=%d respawns=%d turnbacks=%d weapon=%d x=%.0f z=%.0f "
                "frame_ms=%.2f\n",
                renderFrame, static_cast<unsigned long long>(c.frame), app.paused ? 1 : 0, c.shots, c.impacts,
                c.fractures, c.bodies, c.pieces, c.awake, c.frozen, c.jobs, c.crashes, c.respawns,
                c.turnBacks, static_cast<int>(app.game.weapon()) + 1, static_cast<double>(vpos.x),
                static_cast<double>(vpos.z), frameMs);
            std::fflush(stdout);
        }
        if (lastFrame)
            break;
    }

    return finishRun(app, audio, report, rendererName, rasterYield.yieldedFrames());
}

} // namespace

int main(int argc, char** argv) {
    App app;
    gApp = &app;
    if (const int status = parseOptions(argc, argv, app.opt); status >= 0)
        return status;
    if (!app.opt.renderBench.empty())
        return renderBench(app.opt);
    RunMode mode;
    if (const int status = setUp(app, mode); status >= 0)
        return status;
    if (!app.opt.join.empty())
        return joinMode(app);
    if (const int status = startGame(app); status >= 0)
        return status;
    if (!app.opt.replay.empty())
        return replayMode(app);
    return frameLoop(app, mode);
}
