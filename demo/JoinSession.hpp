#pragma once
/// \file JoinSession.hpp
/// `rubble-demo --join HOST:PORT`: a window that follows a host's game (docs/netplay.md). The client cuts
/// the pieces itself from the host's journal events and draws them where the host's placements put them.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "GlContext.hpp"
#include "Math.hpp"
#include "Renderer.hpp"
#include "rubble/rubble.hpp"

namespace demo {

/// What --join needs from the command line.
struct JoinOptions {
    std::string address;                     ///< host address (loopback only)
    std::uint16_t port = 0;                  ///< host port
    int workers = -1;                        ///< fracture workers of the client world
    std::string out;                         ///< folder for screenshots (empty: none)
    double screenshotEvery = 0;              ///< host seconds between screenshots (0: none)
    bool stats = false;                      ///< print a stats line every statsEvery drawn frames
    int statsEvery = 30;                     ///< drawn frames between stats lines
    double fireEvery = 0;                    ///< seconds between automatic shots (0: only Space fires)
    std::optional<std::pair<V3, V3>> camera; ///< --camera: a fixed (eye, target) instead of the orbit
};

/// Splits "HOST:PORT"; false with a message naming the bad part.
bool parseHostPort(const std::string& text, std::string& address, std::uint16_t& port, std::string& error);

/// Follows the host until it closes the connection (or Esc, or the window closes), drawing the scene's
/// ground and sky and the client world's objects; Space (or every fireEvery seconds) asks the host for a shot
/// from the camera at an object. When the host stops, keeps the game in `out` (game.rbsn + game.rbj) and says
/// so. Prints a `join:` summary line. Returns 0 when the client
/// joined and every sync's geometry hash matched the host's, else 1.
int runJoin(const JoinOptions& options, GlContext& gl, Renderer& renderer, const rubble::SceneConfig& scene);

} // namespace demo
