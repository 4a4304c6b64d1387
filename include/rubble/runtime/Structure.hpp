#pragma once
/// \file Structure.hpp
/// A structure without a physics engine (as Blast's stress solver stands beside any engine): static bodies,
/// bonded where they touch, solved under gravity and loads at every step; the bonds that break and the bodies
/// that fall come back as records. DestructionRuntime runs the same inside (docs/structure.md).

#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Frame.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble {

/// What one Structure::step did: a self-contained record.
struct RUBBLE_API StructureStep {
    std::vector<StructureBreak> breaks;       ///< bonds broken, in the order they broke
    std::vector<StructureCollapse> collapses; ///< bodies no bond holds up any more, ascending id (they left)
    double residual = 0;                      ///< relative residual of the step's last solve
};

/// Static bodies bonded where they touch (faces coplanar and facing: BondSettings), under gravity, loads and
/// impact damage. Bodies rest on each other as bearings (StructurePolicy::bearingFriction; 0: welded).
class RUBBLE_API Structure {
public:
    /// A structure with these settings (StructurePolicy::enabled is ignored).
    explicit Structure(const StructurePolicy& policy = {});
    ~Structure();
    Structure(Structure&&) noexcept;
    Structure& operator=(Structure&&) noexcept;

    /// Adds a body, or replaces one with this id: convex parts in world coordinates and a material preset
    /// (empty: concrete); a root is held (the ground). InvalidInput, changing nothing, for id 0, an unknown
    /// material, no parts or a part without volume.
    Status add(BodyId id, const std::vector<ConvexPolytope>& worldParts, std::string_view material = {},
               bool root = false);
    /// Adds a body as a closed mesh's convex parts (decompose() with its defaults) placed at `placement`
    /// (world ← mesh); InvalidInput, changing nothing, also for a placement that is no rigid motion.
    Status add(BodyId id, const Mesh& mesh, const Frame& placement, std::string_view material = {},
               bool root = false);
    /// Removes a body and its bonds; false when it holds none with this id.
    bool remove(BodyId id);
    /// True when it holds a body with this id.
    bool contains(BodyId id) const;
    /// Bodies held.
    std::size_t size() const;
    /// A force (N) at a world point on a body for the next step (a contact, a weight put on it).
    void addLoad(BodyId id, const Vec3& force, const Vec3& point);
    /// Weakens the bonds within StructurePolicy::damageRadius of a hit by its impulse (N·s), at the next
    /// step.
    void damage(const Vec3& point, double impulse);
    /// Solves under gravity (m/s²) and breaks the overstressed bonds; the bodies that lost their support
    /// leave the structure (the caller lets them fall).
    StructureStep step(const Vec3& gravity = {0, -9.81, 0});
    /// The intact bonds with their stress, ordered by (a, b).
    std::vector<StructureBond> bonds() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace rubble
