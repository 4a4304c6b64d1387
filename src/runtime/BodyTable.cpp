#include "runtime/BodyTable.hpp"

namespace rubble::detail {

void BodyTable::count(const BodyRecord& r, int sign) {
    if (r.role == BodyRole::Piece)
        pieces_ += sign;
    if (!r.isDebris())
        return;
    std::set<BodyId>& ids = r.motion == BodyMotionState::Dynamic ? awakeIds_ : frozenIds_;
    if (sign > 0)
        ids.insert(r.id);
    else
        ids.erase(r.id);
    if (sign > 0)
        debrisTriangles_ += r.triangles;
    else
        debrisTriangles_ -= r.triangles;
}

BodyRecord& BodyTable::insert(const BodyRecord& record) {
    BodyRecord& r = records_[record.id] = record;
    if (r.hasObject)
        byObject_[r.object] = r.id;
    count(r, +1);
    return r;
}

void BodyTable::erase(BodyId id) {
    auto it = records_.find(id);
    if (it == records_.end())
        return;
    count(it->second, -1);
    if (it->second.hasObject)
        byObject_.erase(it->second.object);
    records_.erase(it);
}

BodyRecord* BodyTable::find(BodyId id) {
    auto it = records_.find(id);
    return it == records_.end() ? nullptr : &it->second;
}

const BodyRecord* BodyTable::find(BodyId id) const {
    auto it = records_.find(id);
    return it == records_.end() ? nullptr : &it->second;
}

const BodyRecord* BodyTable::findObject(ObjectId id) const {
    auto it = byObject_.find(id);
    return it == byObject_.end() ? nullptr : find(it->second);
}

void BodyTable::setMotion(BodyRecord& record, BodyMotionState motion) {
    count(record, -1);
    record.motion = motion;
    count(record, +1);
}

} // namespace rubble::detail
