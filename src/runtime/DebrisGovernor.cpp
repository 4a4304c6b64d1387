#include "runtime/DebrisGovernor.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace rubble::detail {
namespace {

constexpr int kSettledFrames = 10;     // a piece falling from rest passes 1 m/s within 6 frames at 60 Hz
constexpr double kCellSize = 4.0;      // m: frozen pieces are small, so a body's neighbourhood is a few cells
constexpr double kMovedFraction = 0.1; // a woken body this far (times its radius) from its place has left it
constexpr double kRestingAcceleration = 0.5; // a resting body's velocity changes by under this g·dt a frame
constexpr double kHoldLow = 0.55;  // the average physics step is held in this band (fractions of the budget)
constexpr double kHoldHigh = 0.75; // so that single frames stay under the budget

std::int64_t cellCoord(double x) {
    return static_cast<std::int64_t>(std::floor(x / kCellSize));
}

std::uint64_t packCell(std::int64_t x, std::int64_t y, std::int64_t z) {
    auto b = [](std::int64_t v) { return static_cast<std::uint64_t>(v & 0x1FFFFF); };
    return b(x) | (b(y) << 21) | (b(z) << 42);
}

} // namespace

std::vector<DebrisGovernor::Cell> DebrisGovernor::cellsOf(const Vec3& lo, const Vec3& hi) const {
    std::vector<Cell> out;
    const std::int64_t x0 = cellCoord(lo.x), x1 = cellCoord(hi.x);
    const std::int64_t y0 = cellCoord(lo.y), y1 = cellCoord(hi.y);
    const std::int64_t z0 = cellCoord(lo.z), z1 = cellCoord(hi.z);
    if ((x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1) > 4096) // a huge box: every frozen body is near
        return {};
    for (std::int64_t x = x0; x <= x1; ++x)
        for (std::int64_t y = y0; y <= y1; ++y)
            for (std::int64_t z = z0; z <= z1; ++z)
                out.push_back(packCell(x, y, z));
    return out;
}

void DebrisGovernor::frozen(BodyId id, const Vec3& center, double radius) {
    thawed(id);
    watched_.erase(id);
    frozen_[id] = {center, radius};
    const Vec3 r{radius, radius, radius};
    for (Cell c : cellsOf(center - r, center + r))
        grid_[c].push_back(id);
}

void DebrisGovernor::thawed(BodyId id) {
    awake_.erase(id);
    light_.erase(id);
    waiting_.erase(id);
    auto it = frozen_.find(id);
    if (it == frozen_.end())
        return;
    const Vec3 r{it->second.radius, it->second.radius, it->second.radius};
    for (Cell c : cellsOf(it->second.center - r, it->second.center + r)) {
        auto g = grid_.find(c);
        if (g == grid_.end())
            continue;
        std::erase(g->second, id);
        if (g->second.empty())
            grid_.erase(g);
    }
    frozen_.erase(it);
}

void DebrisGovernor::woken(BodyId id, const Vec3& center, double radius, double margin) {
    watched_[id] = {center, radius, margin};
}

void DebrisGovernor::removed(BodyId id) {
    thawed(id);
    watched_.erase(id);
}

void DebrisGovernor::wakeNear(const Aabb& box, double margin) {
    if (box.empty() || frozen_.empty())
        return;
    const Vec3 m{margin, margin, margin};
    const Vec3 lo = box.lo - m, hi = box.hi + m;
    auto near = [&](BodyId id) {
        const FrozenEntry& e = frozen_.at(id);
        for (int k = 0; k < 3; ++k)
            if (e.center[k] + e.radius < lo[k] || e.center[k] - e.radius > hi[k])
                return false;
        return true;
    };
    const std::vector<Cell> cells = cellsOf(lo, hi);
    if (cells.empty() && !box.empty()) { // a huge box
        for (const auto& [id, e] : frozen_)
            if (near(id))
                waiting_.insert(id);
        return;
    }
    for (Cell c : cells)
        if (auto g = grid_.find(c); g != grid_.end())
            for (BodyId id : g->second)
                if (near(id))
                    waiting_.insert(id);
}

GovernorActions DebrisGovernor::update(const BodyTable& bodies, const PhysicsBinding& binding,
                                       const std::map<BodyId, double>& frozenHits, double physicsMs,
                                       bool deterministic, const Vec3& focus, double dt) {
    GovernorActions out;
    std::set<BodyId> woken;
    for (const auto& [id, impulse] : frozenHits)
        if (impulse >= budget_.wakeImpulse)
            woken.insert(id);
    for (auto it = watched_.begin(); it != watched_.end();) { // woken bodies that left their place
        const WokenEntry& w = it->second;
        if (length(binding.motion(it->first).transform.translation - w.center) <= kMovedFraction * w.radius) {
            ++it;
            continue;
        }
        const Vec3 r{w.radius, w.radius, w.radius};
        wakeNear(Aabb{w.center - r, w.center + r}, w.margin);
        it = watched_.erase(it);
    }
    auto isFrozen = [&](BodyId id) {
        const BodyRecord* r = bodies.find(id);
        return r && r->motion == BodyMotionState::Frozen;
    };
    // What lost its support wakes within the awake budget (light pieces are outside it); the rest waits,
    // frozen: a wake over the budget only turns another moving piece light, whose fall wakes more.
    int room = awakeBudget() - (bodies.awake() - static_cast<int>(light_.size())) -
               static_cast<int>(std::count_if(woken.begin(), woken.end(), isFrozen));
    for (auto it = waiting_.begin(); it != waiting_.end() && room > 0; it = waiting_.erase(it))
        if (isFrozen(*it) && woken.insert(*it).second)
            --room;
    for (BodyId id : woken)
        if (isFrozen(id))
            out.wake.push_back(id);

    const Vec3 g = binding.gravity();
    std::set<BodyId> leaving;
    struct Awake {
        double volume, speed;
        bool settled; // slow for kSettledFrames: resting on something, not at the top of a fall
        bool young;   // awake for fewer frames: it may yet settle, so it is not retired
        bool light;   // collides with static bodies only: outside the awake budget
        BodyId id;
    };
    std::vector<Awake> stillAwake; // pieces: the game's own objects are never retired
    int awakeObjects = 0;
    for (BodyId id : bodies.awakeIds()) {
        const BodyRecord& r = *bodies.find(id);
        const BodyMotion m = binding.motion(id);
        const Vec3 p = m.transform.translation;
        if (p.y < budget_.killBelowY) {
            out.retire.push_back({id, RetireReason::FellOut});
            leaving.insert(id);
            continue;
        }
        const bool piece = r.role == BodyRole::Piece;
        if (piece && r.volume < budget_.fadeVolume && length(p - focus) > budget_.fadeDistance) {
            out.retire.push_back({id, RetireReason::Fade});
            leaving.insert(id);
            continue;
        }
        // Resting: slow, and not gaining speed (a body in flight, or starting to fall, gains g·dt a frame).
        Watch& w = awake_[id];
        const bool steady =
            w.rest >= 0 && length(m.linearVelocity - w.velocity) < kRestingAcceleration * length(g) * dt;
        const bool resting = steady && length(m.linearVelocity) < budget_.freezeSpeed &&
                             length(m.angularVelocity) < budget_.freezeSpeed;
        w.rest = resting ? w.rest + 1 : 0;
        w.velocity = m.linearVelocity;
        const int rest = w.rest;
        const double speed = std::max(length(m.linearVelocity), length(m.angularVelocity));
        w.settle = speed < budget_.settlingSpeed ? w.settle + 1 : 0;
        const int settle = w.settle;
        const int age = ++w.awake;
        if ((budget_.freezeSleeping && m.sleeping) || rest >= std::max(1, budget_.freezeAfterFrames)) {
            out.freeze.push_back(id);
            leaving.insert(id);
            continue;
        }
        if (piece)
            stillAwake.push_back(
                {r.volume, speed, settle >= kSettledFrames, age<kSettledFrames, light_.count(id)> 0, id});
        else
            ++awakeObjects;
    }

    if (!deterministic && budget_.physicsBudgetMs > 0) { // shrink fast, grow back slowly
        smoothedMs_ = smoothedMs_ <= 0 ? physicsMs : 0.9 * smoothedMs_ + 0.1 * physicsMs;
        const double limit = budget_.physicsBudgetMs;
        int b = awakeBudget();
        // Load: a step over the budget on an average in the band, or two in a row (docs/architecture.md).
        const bool over = physicsMs > limit;
        const bool load = over && (lastOver_ || smoothedMs_ > kHoldLow * limit);
        lastOver_ = over;
        if (load || smoothedMs_ > kHoldHigh * limit)
            b = std::min(b, static_cast<int>(
                                0.9 * static_cast<double>(bodies.awake() - static_cast<int>(light_.size()))));
        else if (smoothedMs_ < kHoldLow * limit && physicsMs < kHoldHigh * limit)
            b += std::max(1, b / 50);
        awakeBudget_ = std::clamp(b, std::min(32, budget_.maxAwakeBodies), budget_.maxAwakeBodies);
    } else {
        awakeBudget_ = -1;
    }
    // Over the awake budget: settled pieces freeze where they are (slowest first), then the smallest of the
    // moving ones become light (while there is room for them) or retire. A piece awake for fewer than
    // kSettledFrames, or slow, is left to settle first. Light pieces are outside the awake budget.
    const int lightCap =
        binding.filtersMovingPairs()
            ? static_cast<int>(std::max(0.0, budget_.lightPerAwake) * static_cast<double>(awakeBudget()))
            : 0;
    int lights = 0, settledLights = 0;
    for (const Awake& a : stillAwake) {
        if (a.light && a.settled) { // over the budget already: slow for long enough, it freezes where it is
            out.freeze.push_back(a.id);
            leaving.insert(a.id);
            ++settledLights;
            continue;
        }
        lights += a.light ? 1 : 0;
    }
    auto shed = [&](const Awake& a) {
        if (lights < lightCap) {
            out.lighten.push_back(a.id);
            light_.insert(a.id);
            ++lights;
        } else {
            out.retire.push_back({a.id, RetireReason::Awake});
            leaving.insert(a.id);
        }
    };
    auto skip = [&](const Awake& a) { return a.light || leaving.count(a.id) || light_.count(a.id); };
    int excess = static_cast<int>(stillAwake.size()) - lights - settledLights +
                 static_cast<int>(out.wake.size()) + awakeObjects - awakeBudget();
    if (excess > 0) {
        std::sort(stillAwake.begin(), stillAwake.end(), [](const Awake& a, const Awake& b) {
            return a.speed < b.speed || (a.speed == b.speed && a.id < b.id);
        });
        for (const Awake& a : stillAwake) {
            if (excess <= 0)
                break;
            if (!a.settled || a.light)
                continue;
            out.freeze.push_back(a.id);
            leaving.insert(a.id);
            --excess;
        }
        std::sort(stillAwake.begin(), stillAwake.end(), [](const Awake& a, const Awake& b) {
            return a.volume < b.volume || (a.volume == b.volume && a.id < b.id);
        });
        for (const Awake& a : stillAwake) {
            if (excess <= 0)
                break;
            if (skip(a) || a.young || a.speed < budget_.settlingSpeed)
                continue; // a slow piece is about to settle and freeze
            shed(a);
            --excess;
        }
        // Beyond the overshoot the budget is hard: the smallest of the waiting pieces retire too.
        for (const Awake& a : stillAwake) {
            if (excess <= std::max(0, budget_.awakeOvershoot))
                break;
            if (skip(a))
                continue;
            shed(a);
            --excess;
        }
    }
    if (lights > lightCap) { // the budget shrank: the smallest light pieces retire
        std::sort(stillAwake.begin(), stillAwake.end(), [](const Awake& a, const Awake& b) {
            return a.volume < b.volume || (a.volume == b.volume && a.id < b.id);
        });
        for (const Awake& a : stillAwake) {
            if (lights <= lightCap)
                break;
            if (!a.light || leaving.count(a.id))
                continue;
            out.retire.push_back({a.id, RetireReason::Awake});
            leaving.insert(a.id);
            --lights;
        }
    }

    std::size_t triangles = bodies.debrisTriangles();
    for (BodyId id : leaving)
        if (std::any_of(out.retire.begin(), out.retire.end(), [&](const auto& r) { return r.first == id; }))
            triangles -= std::min(triangles, bodies.find(id)->triangles);
    if (triangles > budget_.maxTriangles) { // the smallest frozen pieces first, then the smallest awake
        std::vector<std::pair<double, BodyId>> candidates;
        for (BodyId id : bodies.frozenIds())
            if (const BodyRecord* r = bodies.find(id); !woken.count(id) && r->role == BodyRole::Piece)
                candidates.push_back({r->volume, id});
        std::sort(candidates.begin(), candidates.end());
        std::vector<std::pair<double, BodyId>> awake;
        for (const Awake& a : stillAwake)
            if (!leaving.count(a.id))
                awake.push_back({a.volume, a.id});
        std::sort(awake.begin(), awake.end());
        candidates.insert(candidates.end(), awake.begin(), awake.end());
        for (const auto& [v, id] : candidates) {
            if (triangles <= budget_.maxTriangles)
                break;
            triangles -= std::min(triangles, bodies.find(id)->triangles);
            out.retire.push_back({id, RetireReason::Triangles});
        }
    }
    for (BodyId id : leaving) {
        awake_.erase(id);
        light_.erase(id);
    }
    return out;
}

} // namespace rubble::detail
