#pragma once
/// \file NetView.hpp
/// The drawing side of `rubble-demo --join`: a client world that follows a host over ENet (NetClient) and
/// keeps one renderer mesh per object, drawn at the host's interpolated placements.

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "Math.hpp"
#include "Renderer.hpp"
#include "rubble/enet/NetClient.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/rubble.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace demo {

/// A followed world and its meshes.
class NetView {
public:
    NetView();
    ~NetView();
    NetView(const NetView&) = delete;
    NetView& operator=(const NetView&) = delete;

    /// Starts connecting to address:port (a loopback address) with a deterministic world of `workers`
    /// fracture workers, holding the scene's objects loaded as rubble-server loads them (the host then sends
    /// those it has unbroken by id); false with a message.
    bool connect(const std::string& address, std::uint16_t port, int workers,
                 const rubble::SceneConfig& scene, std::string& error);
    /// Receives what arrived within timeoutMs; an IoError once the connection ended (the host closed it or
    /// never answered), another error when the host sent something the world refused.
    rubble::Status service(int timeoutMs);
    /// Queues every object at its placement two placement periods behind the latest sync (so that it is
    /// interpolated between the host's placements even when one was lost); renderer meshes follow the world's
    /// objects.
    void draw(Renderer& renderer, int texture, float dt);
    /// Asks the host to fire a shot from `eye` at the centre of a destructible object it draws (the
    /// index-th of them, counted round), at 120 m/s; the host checks it first. False when there is none.
    bool shoot(const V3& eye, int index);
    /// Keeps the game so far (NetClient::writeReplay) as folder/game.rbsn and folder/game.rbj.
    rubble::Status writeReplay(const std::string& folder) const;
    /// Frees the renderer meshes.
    void clear(Renderer& renderer);

    /// Centre and radius of what the snapshot held (the camera orbits it); radius 0 before the join.
    void bounds(V3& centre, float& radius) const;
    /// The client's totals.
    const rubble::net::ClientStats& stats() const;
    /// The client world's geometry hash.
    std::uint64_t geometryHash() const;
    /// Objects drawn in the last draw().
    int drawn() const { return drawn_; }

    /// Host frames between two placement messages (the host sends them every 6th frame).
    static constexpr double kPlacementPeriod = 6;
    /// Host frames it shows behind the latest sync (docs/netplay.md, 'Measured': lag 12).
    static constexpr double kViewLag = 2 * kPlacementPeriod;

private:
    struct Visual {
        int mesh = -1;             ///< renderer mesh (object coordinates)
        std::uint32_t version = 0; ///< the object's version the mesh was made from
        float heat = 0;            ///< glow of fresh cut faces
    };
    std::unique_ptr<rubble::DestructionWorld> world_;
    std::unique_ptr<rubble::net::NetClient> client_;
    std::map<rubble::ObjectId, Visual> visuals_;
    std::map<rubble::ObjectId, float> fresh_; // pieces adopted since the last draw: they start glowing
    bool framed_ = false;                     // bounds taken from the snapshot
    V3 centre_;
    float radius_ = 0;
    int drawn_ = 0;
};

} // namespace demo
