#pragma once
/// \file LocalFracture.hpp
/// Stand-in fracture service used while the DestructionWorld runtime is not linked: one irregular convex cell
/// at the impact (Rubble's fast convex-cell clipper), remainder islands plus the cut chunk split by two
/// random planes, each piece re-centred on its exact centre of mass. Jobs run on std::async workers; in
/// deterministic mode a result is adopted exactly `delayFrames` after its impact.

#include <chrono>
#include <cstdint>
#include <future>
#include <vector>

#include "rubble/Mesh.hpp"

namespace demo {

/// One piece of a fracture, in the parent's local coordinates shifted to its own centre of mass.
struct LocalPiece {
    rubble::Mesh mesh;    ///< closed mesh, origin at its centre of mass
    rubble::Vec3 offset;  ///< centre of mass in the parent's local coordinates
    double volume = 0;    ///< volume
    rubble::Vec3 inertia; ///< diagonal of the inertia tensor about the centre of mass, density 1
    bool debris = false;  ///< cut out of the cell (false: remainder)
};

/// The outcome of one job.
struct LocalFractureResult {
    std::uint32_t key = 0;          ///< caller's id of the broken body
    std::vector<LocalPiece> pieces; ///< empty when the cut failed or missed
    double ms = 0;                  ///< wall-clock time of the job
    std::uint64_t frame = 0;        ///< frame of the impact
    double latencyMs = 0;           ///< wall-clock time from submission to collection
};

/// Asynchronous fracture jobs.
class LocalFracture {
public:
    /// Queues a job: mesh in local coordinates, impact point/normal local, cell edge length.
    void submit(std::uint32_t key, const rubble::Mesh& mesh, const rubble::Vec3& point,
                const rubble::Vec3& normal, double cellSize, std::uint64_t seed, std::uint64_t frame);
    /// Results ready at this frame.
    std::vector<LocalFractureResult> collect(std::uint64_t frame);
    /// True when a job for key is running.
    bool busy(std::uint32_t key) const;
    /// Jobs in flight.
    int inFlight() const { return static_cast<int>(jobs_.size()); }
    /// Deterministic adoption (fixed delay); otherwise results adopt as soon as they are ready.
    bool deterministic = false;
    /// Delay in frames for deterministic mode.
    int delayFrames = 2;
    /// Pure function computing one job (also used synchronously).
    static LocalFractureResult run(std::uint32_t key, rubble::Mesh mesh, rubble::Vec3 point,
                                   rubble::Vec3 normal, double cellSize, std::uint64_t seed);

private:
    struct Job {
        std::uint32_t key;
        std::uint64_t frame;
        std::future<LocalFractureResult> future;
        std::chrono::steady_clock::time_point submitted;
    };
    std::vector<Job> jobs_;
};

} // namespace demo
