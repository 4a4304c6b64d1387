#include "JoinSession.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "GroundMesh.hpp"
#include "NetView.hpp"
#include "RunReport.hpp"

namespace demo {

bool parseHostPort(const std::string& text, std::string& address, std::uint16_t& port, std::string& error) {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
        error = "--join " + text + ": expected HOST:PORT";
        return false;
    }
    const std::string digits = text.substr(colon + 1);
    long value = 0;
    for (char c : digits) {
        if (c < '0' || c > '9' || value > 65535) {
            error = "--join " + text + ": port '" + digits + "' is not a number in 1..65535";
            return false;
        }
        value = value * 10 + (c - '0');
    }
    if (value < 1 || value > 65535) {
        error = "--join " + text + ": port '" + digits + "' is not a number in 1..65535";
        return false;
    }
    address = text.substr(0, colon);
    port = static_cast<std::uint16_t>(value);
    return true;
}

int runJoin(const JoinOptions& options, GlContext& gl, Renderer& renderer, const rubble::SceneConfig& scene) {
    using Clock = std::chrono::steady_clock;
    NetView view;
    std::string error;
    if (!view.connect(options.address, options.port, options.workers, scene, error)) {
        std::fprintf(stderr, "error: cannot join %s:%u: %s\n", options.address.c_str(), options.port,
                     error.c_str());
        return 1;
    }
    std::printf("join: connecting to %s:%u\n", options.address.c_str(), options.port);
    std::fflush(stdout);
    std::vector<std::string> warnings;
    int ground = -1;
    M4 groundModel;
    float groundTop = -1e30f;
    if (scene.ground.line != 0) { // the ground is no object of the world: the client draws the scene's
        const auto& g = scene.ground;
        const int texture = g.textureFound ? renderer.loadTexture(g.texturePath, "grid", warnings)
                                           : renderer.proceduralTexture("grid");
        ground = renderer.addMesh(groundMesh(g), texture, 0.95f, 1.0f, 0.92f);
        groundModel = translateScale({static_cast<float>(g.position.x), static_cast<float>(g.position.y),
                                      static_cast<float>(g.position.z)},
                                     {1, 1, 1});
        groundTop = static_cast<float>(g.position.y + std::abs(g.scale.y) * 0.5);
    }
    const int texture = renderer.proceduralTexture("concrete");
    if (!options.out.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(options.out, ec);
    }

    float yaw = 0.6f, zoom = 1.0f;
    long framesDrawn = 0, renderFrames = 0;
    int screenshots = 0;
    long nextShot = 0; // host frame of the next screenshot
    bool userClosed = false, spaceDown = false;
    rubble::Status ending;
    auto last = Clock::now();
    auto lastShot = last;
    int shots = 0;
    while (true) {
        const auto now = Clock::now();
        const float dt = std::min(0.1f, std::chrono::duration<float>(now - last).count());
        last = now;
        if (GLFWwindow* w = gl.window()) {
            glfwPollEvents();
            if (glfwWindowShouldClose(w) || glfwGetKey(w, GLFW_KEY_ESCAPE) == GLFW_PRESS) {
                userClosed = true;
                break;
            }
            auto down = [w](int k) { return glfwGetKey(w, k) == GLFW_PRESS; };
            const float turn = (down(GLFW_KEY_A) ? 1.0f : 0.0f) - (down(GLFW_KEY_D) ? 1.0f : 0.0f);
            yaw += (turn != 0 ? turn : 0.08f) * dt; // A/D orbit, else a slow turn
            zoom *= std::exp(((down(GLFW_KEY_S) ? 1.0f : 0.0f) - (down(GLFW_KEY_W) ? 1.0f : 0.0f)) * dt);
            zoom = std::clamp(zoom, 0.2f, 5.0f);
        }
        if (ending = view.service(5); !ending)
            break;

        renderer.beginFrame();
        if (ground >= 0)
            renderer.drawMesh(ground, groundModel);
        view.draw(renderer, texture, dt);
        V3 centre;
        float radius = 0;
        view.bounds(centre, radius);
        const float distance = (radius > 0 ? radius * 2.2f : 60.0f) * zoom;
        FrameView fv;
        fv.width = gl.width();
        fv.height = gl.height();
        fv.fbo = gl.framebuffer();
        fv.eye = centre + V3{std::sin(yaw) * distance, 0.45f * distance, std::cos(yaw) * distance};
        fv.eye.y = std::max(fv.eye.y, groundTop + 1.5f);
        if (options.camera) {
            fv.eye = options.camera->first;
            centre = options.camera->second;
        }
        fv.view = lookAt(fv.eye, centre, V3{0, 1, 0});
        fv.proj = perspective(
            1.05f, static_cast<float>(fv.width) / static_cast<float>(std::max(fv.height, 1)), 0.5f, 3000.0f);
        fv.focus = centre;
        renderer.render(fv);
        ++renderFrames;
        bool fire =
            options.fireEvery > 0 && now - lastShot >= std::chrono::duration<double>(options.fireEvery);
        if (GLFWwindow* w = gl.window()) { // Space: one shot per press
            const bool down = glfwGetKey(w, GLFW_KEY_SPACE) == GLFW_PRESS;
            fire = fire || (down && !spaceDown);
            spaceDown = down;
        }
        if (fire && view.shoot(fv.eye, shots)) {
            ++shots;
            lastShot = now;
        }
        framesDrawn += view.drawn() > 0;

        const rubble::net::ClientStats& st = view.stats();
        const long shotEvery = std::lround(options.screenshotEvery * 60);
        if (!options.out.empty() && shotEvery > 0 && view.drawn() > 0 &&
            static_cast<long>(st.frame) >= nextShot) {
            std::string rgb;
            int sw = 0, sh = 0;
            gl.readPixels(rgb, sw, sh);
            char name[64];
            std::snprintf(name, sizeof name, "join_%04d.png", ++screenshots);
            const auto path = std::filesystem::path(options.out) / name;
            if (writePng(path, rgb, sw, sh))
                std::printf("screenshot %s frame=%llu shown=%lld\n", path.string().c_str(),
                            static_cast<unsigned long long>(st.frame),
                            static_cast<long long>(st.frame) - static_cast<long long>(NetView::kViewLag));
            nextShot = (static_cast<long>(st.frame) / shotEvery + 1) * shotEvery;
        }
        gl.present();
        if (options.stats && renderFrames % std::max(1, options.statsEvery) == 0)
            std::printf("stats render=%ld frame=%llu drawn=%d events=%lld syncs=%lld mismatched=%lld\n",
                        renderFrames, static_cast<unsigned long long>(st.frame), view.drawn(), st.events,
                        st.syncs, st.mismatchedHashes);
        std::fflush(stdout);
    }

    const rubble::net::ClientStats& st = view.stats();
    const bool hostClosed = !ending && ending.error().code == rubble::ErrorCode::IoError && st.joined;
    if (hostClosed && !options.out.empty()) {
        const rubble::Status kept = view.writeReplay(options.out);
        std::printf("join: the host stopped; %s%s\n",
                    kept ? "the game so far is in " : "cannot keep the game: ",
                    kept ? (options.out + "/game.rbsn + game.rbj").c_str() : kept.message().c_str());
    }
    std::printf("join: %s; joined %s (%.0f ms), %lld events, %lld syncs checked, %lld mismatched hashes, "
                "%lld placements, %ld frames drawn, %d shots asked, geometry hash %016llx\n",
                userClosed ? "closed" : ending.message().c_str(), st.joined ? "yes" : "no", st.joinMs,
                st.events, st.syncs, st.mismatchedHashes, st.placements, framesDrawn, shots,
                static_cast<unsigned long long>(view.geometryHash()));
    std::fflush(stdout);
    view.clear(renderer);
    if (ground >= 0)
        renderer.removeMesh(ground);
    return st.joined && st.mismatchedHashes == 0 && (userClosed || hostClosed) ? 0 : 1;
}

} // namespace demo
