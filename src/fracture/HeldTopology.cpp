#include <memory>
#include <utility>

#include "geometry/MeshTopology.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {

HeldTopology::HeldTopology() noexcept = default;

HeldTopology::HeldTopology(MeshTopology&& topology) {
    if (!topology.twin.empty())
        held_ = std::make_unique<MeshTopology>(std::move(topology));
}

HeldTopology::HeldTopology(const HeldTopology& other)
    : held_(other.empty() ? nullptr : std::make_unique<MeshTopology>(*other.held_)) {}

HeldTopology::HeldTopology(HeldTopology&& other) noexcept = default;

HeldTopology& HeldTopology::operator=(const HeldTopology& other) {
    if (this != &other)
        held_ = other.empty() ? nullptr : std::make_unique<MeshTopology>(*other.held_);
    return *this;
}

HeldTopology& HeldTopology::operator=(HeldTopology&& other) noexcept = default;

HeldTopology::~HeldTopology() = default;

bool HeldTopology::empty() const {
    return !held_ || held_->twin.empty();
}

bool HeldTopology::fits(const Mesh& mesh) const {
    return held_ && held_->fits(mesh);
}

bool HeldTopology::operator==(const HeldTopology& other) const {
    return empty() ? other.empty() : !other.empty() && *held_ == *other.held_;
}

} // namespace rubble
