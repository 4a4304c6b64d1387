#pragma once
// The runtime's bodies by id and by object, with the counts the debris governor budgets.

#include <map>
#include <set>
#include <unordered_map>

#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble::detail {

/// Every body of a runtime, in id order, with incrementally kept counts.
class BodyTable {
public:
    /// Adds a record (its id must be new).
    BodyRecord& insert(const BodyRecord& record);
    /// Removes a record.
    void erase(BodyId id);
    /// The record, or null.
    BodyRecord* find(BodyId id);
    /// The record, or null.
    const BodyRecord* find(BodyId id) const;
    /// The body carrying an object, or null.
    const BodyRecord* findObject(ObjectId id) const;
    /// Changes a body's motion state, keeping the counts.
    void setMotion(BodyRecord& record, BodyMotionState motion);
    /// Every record, in id order.
    const std::map<BodyId, BodyRecord>& all() const { return records_; }
    /// Piece bodies.
    int pieces() const { return pieces_; }
    /// Dynamic debris bodies.
    int awake() const { return static_cast<int>(awakeIds_.size()); }
    /// Frozen debris bodies.
    int frozen() const { return static_cast<int>(frozenIds_.size()); }
    /// Triangles of debris bodies.
    std::size_t debrisTriangles() const { return debrisTriangles_; }
    /// Dynamic debris bodies, ascending.
    const std::set<BodyId>& awakeIds() const { return awakeIds_; }
    /// Frozen debris bodies, ascending.
    const std::set<BodyId>& frozenIds() const { return frozenIds_; }

private:
    void count(const BodyRecord& r, int sign);

    std::map<BodyId, BodyRecord> records_;
    std::unordered_map<ObjectId, BodyId> byObject_;
    int pieces_ = 0;
    std::set<BodyId> awakeIds_;
    std::set<BodyId> frozenIds_;
    std::size_t debrisTriangles_ = 0;
};

} // namespace rubble::detail
