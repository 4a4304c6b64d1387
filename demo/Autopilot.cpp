#include "Autopilot.hpp"

#include <algorithm>
#include <cmath>

namespace demo {

ControlInput Autopilot::update(const Game& game, float dt) {
    ControlInput in;
    V3 pos, fwd, up;
    game.vehicleFrame(pos, fwd, up);
    const V3 right = norm(cross(fwd, up));
    const float alt = pos.y - game.groundY();
    in.weapon = static_cast<int>(autopilotWeapon(game.counters().shots)); // two shots of each in turn
    in.throttle = game.speed() < 34 ? 1.0f : (game.speed() > 40 ? -1.0f : 0.0f);

    retarget_ -= dt;
    if (!hasTarget_ || retarget_ <= 0) {
        const auto targets = game.targets();
        float best = 1e30f;
        hasTarget_ = false;
        for (const V3& t : targets) {
            const V3 d = t - pos;
            const float dist = len(d);
            if (dist < 60)
                continue;
            // Prefer targets ahead: distance plus a penalty for turning.
            const float score = dist * (1.6f - dot(norm(d), fwd));
            if (score < best) {
                best = score;
                target_ = t;
                hasTarget_ = true;
            }
        }
        retarget_ = 1.5f;
    }

    if (evade_ > 0) {
        evade_ -= dt;
        in.pitch = fwd.y < 0.5f ? -1.0f : 0.0f;
        in.yaw = evadeYaw_;
    } else if (hasTarget_) {
        V3 aim = target_;
        aim.y = std::max(aim.y, game.groundY() + 6);
        const V3 d = norm(aim - pos);
        const float x = dot(d, right), y = dot(d, up), z = dot(d, fwd);
        in.yaw = std::clamp(-x * 4.0f, -1.0f, 1.0f);
        in.pitch = std::clamp(-y * 4.0f, -1.0f, 1.0f);
        if (z < 0) {
            in.yaw = x < 0 ? 1.0f : -1.0f;
        }
        const float dist = len(target_ - pos);
        // fire when the line of fire passes within 3 m of the centre of a standing object clear of the ground
        const V3 shot = norm(game.shotVelocity()); // the jet's velocity lags its nose in turns
        for (const V3& t : game.targets()) {
            if (t.y < game.groundY() + 5)
                continue;
            const float along = dot(t - pos, shot);
            const float miss = len(t - pos - shot * along);
            in.fire = in.fire || (along > 20 && along < 260 && miss < 3.0f);
        }
        if (dist < 55) {
            evade_ = 2.2f;
            evadeYaw_ = x < 0 ? -1.0f : 1.0f;
            hasTarget_ = false;
            retarget_ = 2.5f;
        }
    } else {
        in.yaw = 0.3f;
    }
    // Ground and ceiling safety.
    if (alt < 14 && fwd.y < 0.15f)
        in.pitch = -1.0f;
    if (alt > 140 && fwd.y > -0.1f)
        in.pitch = 1.0f;
    return in;
}

} // namespace demo
