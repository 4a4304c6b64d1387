#pragma once
// Private: the placements a client received of each body, by host frame, and where a body is at any frame
// (docs/netplay.md, 'Placements'): interpolated between them, held before a body began to move, carried on
// at its last velocity past the newest one while no later publish has shown it at rest.

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <map>
#include <utility>
#include <vector>

#include "Protocol.hpp"
#include "rubble/core/Frame.hpp"

namespace rubble::net::detail {

/// Host frames of placements kept per body: a client whose world lags the placements it receives (it is still
/// cutting pieces) can show any frame of the last two seconds between two placements.
inline constexpr double kTrackFrames = 120;
/// How far past its newest placement a body is carried on, in publish periods; further on, it has most
/// likely stopped (the datagrams since that would say so were lost) and is held.
inline constexpr double kExtrapolatePeriods = 2;

/// The placements datagrams a client received: their seqs and frames, and the host's publish period.
class PublishLog {
public:
    /// A datagram arrived.
    void received(std::uint32_t seq, double frame) {
        if (!seqs_.empty() && frame > newest_)
            period_ = period_ > 0 ? std::min(period_, frame - newest_) : frame - newest_;
        newest_ = std::max(newest_, frame);
        seqs_[seq] = frame;
        while (seqs_.size() > 256)
            seqs_.erase(seqs_.begin());
    }
    /// Frames between two publishes (the smallest gap seen; 0 until two were seen).
    double period() const { return period_; }
    /// The newest frame of a datagram received (-1: none).
    double newest() const { return newest_; }
    /// True when every datagram the host sent between frames a and b (exclusive) arrived: the seqs from the
    /// newest received at or before a to the oldest received at or after b are all there.
    bool arrivedAll(double a, double b) const {
        std::uint32_t from = 0, to = 0;
        bool hasFrom = false, hasTo = false;
        for (const auto& [seq, frame] : seqs_) {
            if (frame <= a) {
                from = seq;
                hasFrom = true;
            } else if (frame >= b && !hasTo) {
                to = seq;
                hasTo = true;
            }
        }
        if (!hasFrom || !hasTo || to < from)
            return false;
        return static_cast<std::uint32_t>(std::distance(seqs_.find(from), seqs_.find(to))) == to - from;
    }

private:
    std::map<std::uint32_t, double> seqs_; // seq → frame, the latest 256 received
    double newest_ = -1;
    double period_ = 0;
};

/// The latest placements of a body, by host frame (ascending, within kTrackFrames of the newest).
struct Track {
    std::vector<std::pair<double, Frame>> points;

    /// A placement of frame `frame`. A body that the host left out of every publish since its previous
    /// placement (all of them arrived) did not move until the last of them: it is held there first.
    void add(double frame, const Frame& f, const PublishLog* log = nullptr) {
        if (!points.empty() && frame < points.back().first - kTrackFrames)
            return; // older than all it keeps
        if (log && !points.empty() && log->period() > 0) {
            const double last = points.back().first, still = frame - log->period();
            if (still > last + 0.5 * log->period() && log->arrivedAll(last, frame))
                insert(still, points.back().second);
        }
        insert(frame, f);
        while (points.size() > 2 && points.front().first < points.back().first - kTrackFrames)
            points.erase(points.begin());
    }

    /// Where it is at `frame`: interpolated between two points, held before the first; after the newest, held
    /// too, unless no later publish has arrived complete (then the body may still move: carried on at the
    /// velocity of its last two points, up to kExtrapolatePeriods past the newest). Not empty.
    Frame at(double frame, const PublishLog* log = nullptr) const {
        if (frame <= points.front().first)
            return points.front().second;
        if (frame >= points.back().first) {
            Frame f = points.back().second;
            if (!log || points.size() < 2 || log->period() <= 0)
                return f;
            const auto& [t1, b] = points.back();
            const auto& [t0, a] = points[points.size() - 2];
            const double period = log->period();
            const double ahead = frame - t1;
            if (t1 - t0 > 1.5 * period || ahead > kExtrapolatePeriods * period)
                return f;
            if (log->newest() > t1 && log->arrivedAll(t1, log->newest()))
                return f; // shown at rest by a later publish
            f.translation = b.translation + (b.translation - a.translation) * (ahead / (t1 - t0));
            return f;
        }
        std::size_t k = 0;
        while (points[k + 1].first < frame)
            ++k;
        const Frame &a = points[k].second, &b = points[k + 1].second;
        const double s = (frame - points[k].first) / (points[k + 1].first - points[k].first);
        Frame f;
        f.translation = a.translation * (1 - s) + b.translation * s;
        auto qa = toQuaternion(a.rotation), qb = toQuaternion(b.rotation);
        const double dot = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3];
        const double sign = dot < 0 ? -1 : 1; // the shorter way round
        std::array<double, 4> q{};
        for (int i = 0; i < 4; ++i)
            q[i] = qa[i] * (1 - s) + sign * qb[i] * s;
        f.rotation = fromQuaternion(q);
        return f;
    }

private:
    void insert(double frame, const Frame& f) {
        auto at = std::lower_bound(points.begin(), points.end(), frame,
                                   [](const auto& p, double x) { return p.first < x; });
        if (at != points.end() && at->first == frame)
            return; // a duplicate
        points.insert(at, {frame, f});
    }
};

} // namespace rubble::net::detail
