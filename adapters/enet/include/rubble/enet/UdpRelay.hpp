#pragma once
/// \file UdpRelay.hpp
/// A seeded network that misbehaves, in user space on 127.0.0.1: a link model (delay, jitter, burst loss,
/// reordering, duplication, a bandwidth cap, a partition window) and a UDP relay that applies one per
/// direction between a client and a server (docs/netplay.md, 'A network that misbehaves').

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "rubble/core/Random.hpp"
#include "rubble/core/Result.hpp"

namespace rubble::net {

/// What one direction of a link does to the datagrams it carries.
struct LinkProfile {
    double delayMs = 0;     ///< one-way delay (mean)
    double jitterMs = 0;    ///< standard deviation of the delay (normal, cut at ±3σ and at 0)
    double loss = 0;        ///< fraction of datagrams lost, in [0, 1)
    double burstLength = 1; ///< mean datagrams per loss burst (Gilbert-Elliott); ≤ 1 = independent losses
    double reorder = 0;     ///< fraction of datagrams held back by reorderMs, so that later ones overtake
    double reorderMs = 20;  ///< extra delay of a held-back datagram
    double duplicate = 0;   ///< fraction of datagrams delivered twice (each copy with its own delay)
    double kbps = 0;        ///< bandwidth cap in kilobits per second (0 = none); excess queues
    double queueMs = 250;   ///< a datagram that would wait longer than this behind the cap is dropped
    double partitionStartS = -1; ///< start of the partition window (seconds since the link started; < 0 none)
    double partitionS = 0;       ///< length of the partition window: every datagram is dropped in it
};

/// Counts of a link.
struct LinkStats {
    long long sent = 0;           ///< datagrams offered to the link
    long long bytesSent = 0;      ///< bytes offered to the link
    long long delivered = 0;      ///< datagrams delivered (copies included)
    long long lost = 0;           ///< dropped by the loss model
    long long partitionDrops = 0; ///< dropped because the link was partitioned when sent or due
    long long queueDrops = 0;     ///< dropped because the bandwidth cap's queue was full
    long long duplicated = 0;     ///< extra copies made
    long long reordered = 0;      ///< held back by reorderMs
    long long bytesDelivered = 0; ///< bytes delivered (copies included)
};

/// One direction of a link, without sockets: decides each datagram's fate from a seeded generator, so the
/// same seed and the same send times give the same deliveries.
class LinkModel {
public:
    /// A link with the given profile and seed.
    LinkModel(const LinkProfile& profile, std::uint64_t seed);
    /// Delivery times (seconds) of a datagram of `bytes` sent at `now` (seconds since the link started):
    /// none when it is dropped, two when it is duplicated.
    std::vector<double> send(double now, std::size_t bytes);
    /// Whether a datagram due at `now` still arrives (false inside the partition window); counts the drop.
    bool deliver(double now, std::size_t bytes);
    /// Whether the link is partitioned at `now` (the profile's window, or setPartitioned).
    bool partitioned(double now) const;
    /// Partitions the link (or heals it) regardless of the profile's window.
    void setPartitioned(bool on);
    /// Its counts.
    const LinkStats& stats() const { return stats_; }
    /// Its profile.
    const LinkProfile& profile() const { return profile_; }

private:
    double delay();
    LinkProfile profile_;
    Rng rng_;
    LinkStats stats_;
    bool bad_ = false;     // Gilbert-Elliott state: in a loss burst
    bool forced_ = false;  // setPartitioned
    double busyUntil_ = 0; // the bandwidth cap's link is busy until then
    double goodToBad_ = 0; // per datagram
    double badToGood_ = 1; // per datagram
};

/// A UDP relay on 127.0.0.1 for one client: datagrams to port() go to the server's port through the `up`
/// link, the server's answers go back to the client through the `down` link. Runs on its own thread.
class UdpRelay {
public:
    /// Starts a relay to 127.0.0.1:serverPort on a free port.
    static Result<std::unique_ptr<UdpRelay>> start(std::uint16_t serverPort, const LinkProfile& up,
                                                   const LinkProfile& down, std::uint64_t seed);
    ~UdpRelay();
    UdpRelay(const UdpRelay&) = delete;
    UdpRelay& operator=(const UdpRelay&) = delete;
    /// The port clients send to.
    std::uint16_t port() const;
    /// Partitions both directions (or heals them), in addition to the profiles' windows.
    void setPartitioned(bool on);
    /// Counts of the client → server link.
    LinkStats up() const;
    /// Counts of the server → client link.
    LinkStats down() const;

private:
    struct Impl;
    explicit UdpRelay(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace rubble::net
