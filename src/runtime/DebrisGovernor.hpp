#pragma once
// Keeps debris affordable (DebrisBudget): freezes resting pieces, wakes them when hit or when what they rest
// on goes, and turns the smallest into particles when a budget is exceeded.

#include <cstdint>
#include <map>
#include <set>
#include <unordered_map>
#include <vector>

#include "rubble/runtime/DestructionRuntime.hpp"
#include "runtime/BodyTable.hpp"

namespace rubble::detail {

/// Why a debris body leaves the simulation.
enum class RetireReason { Awake, Triangles, Fade, FellOut };

/// What the governor decided for one frame, in a deterministic order.
struct GovernorActions {
    std::vector<BodyId> freeze;                          ///< make static
    std::vector<BodyId> wake;                            ///< make dynamic again
    std::vector<BodyId> lighten;                         ///< collide with static bodies only
    std::vector<std::pair<BodyId, RetireReason>> retire; ///< turn into particles
};

/// The debris governor. Frozen bodies are kept in a grid so that the ones near a body that moves away or
/// breaks can be woken.
class DebrisGovernor {
public:
    /// Reads the budget at every call.
    explicit DebrisGovernor(const DebrisBudget& budget) : budget_(budget) {}

    /// The decisions of a frame of dt seconds. frozenHits: strongest contact impulse on frozen bodies this
    /// frame; physicsMs: this frame's physics step (ignored when deterministic).
    GovernorActions update(const BodyTable& bodies, const PhysicsBinding& binding,
                           const std::map<BodyId, double>& frozenHits, double physicsMs, bool deterministic,
                           const Vec3& focus, double dt);
    /// A body was frozen at center with the given bounding radius.
    void frozen(BodyId id, const Vec3& center, double radius);
    /// A body stopped being frozen (woken or removed).
    void thawed(BodyId id);
    /// A frozen body was woken at center; its old neighbourhood (within margin) wakes once it leaves there.
    void woken(BodyId id, const Vec3& center, double radius, double margin);
    /// A body left the simulation.
    void removed(BodyId id);
    /// Frozen bodies whose bounds come within `margin` of the box (they lose what they rest on when a body
    /// there moves or breaks); they are woken at the next update that has awake budget to spare for them.
    void wakeNear(const Aabb& box, double margin);
    /// Frozen bodies waiting for awake budget to wake (wakeNear), ascending.
    const std::set<BodyId>& waiting() const { return waiting_; }
    /// The awake budget in force.
    int awakeBudget() const { return awakeBudget_ < 0 ? budget_.maxAwakeBodies : awakeBudget_; }
    /// Light pieces (over the awake budget, colliding with static bodies only), ascending.
    const std::set<BodyId>& light() const { return light_; }

private:
    using Cell = std::uint64_t;
    struct FrozenEntry {
        Vec3 center;
        double radius = 0;
    };
    std::vector<Cell> cellsOf(const Vec3& lo, const Vec3& hi) const;

    const DebrisBudget& budget_;
    struct Watch {      // an awake body's history
        int rest = -1;  // frames in a row slow and not accelerating (-1: no velocity seen yet)
        Vec3 velocity;  // linear velocity at the last update
        int settle = 0; // frames below settlingSpeed in a row
        int awake = 0;  // frames awake since adopted or woken
    };
    std::unordered_map<BodyId, Watch> awake_;
    struct WokenEntry {
        Vec3 center;
        double radius = 0, margin = 0;
    };
    std::map<BodyId, FrozenEntry> frozen_;
    std::map<BodyId, WokenEntry> watched_; // woken bodies whose old neighbourhood still rests on their place
    std::unordered_map<Cell, std::vector<BodyId>> grid_;
    std::set<BodyId> waiting_; // frozen bodies to wake once the awake budget has room
    std::set<BodyId> light_;
    int awakeBudget_ = -1;  // < 0: the configured maximum
    double smoothedMs_ = 0; // moving average of the physics step
    bool lastOver_ = false; // the previous frame's step was over the budget
};

} // namespace rubble::detail
