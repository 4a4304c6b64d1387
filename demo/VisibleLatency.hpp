#pragma once
/// \file VisibleLatency.hpp
/// Impact → visible: each adopted fracture's impact → adopted time plus the wait until the frame that draws
/// its pieces is presented.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace demo {

/// Adopted fractures waiting for their first presented frame, and those already shown.
class VisibleLatency {
public:
    using Clock = std::chrono::steady_clock;
    /// One adopted fracture.
    struct Record {
        std::uint64_t object = 0; ///< the object that broke (TimingRecord::object)
        std::uint64_t frame = 0;  ///< frame of its impact (TimingRecord::frame)
        double adoptedMs = 0;     ///< impact → adopted (TimingRecord::totalMs)
        double shownMs = 0;       ///< adopted → the frame that draws its pieces presented
        double visibleMs() const { return adoptedMs + shownMs; }
    };
    /// A fracture adopted at `at`; it becomes visible at the next presented().
    void adopted(std::uint64_t object, std::uint64_t frame, double adoptedMs, Clock::time_point at);
    /// A frame was presented at `at`: every fracture adopted before it is visible now.
    void presented(Clock::time_point at);
    /// Forgets everything (a new scene).
    void clear();
    /// Fractures shown so far.
    const std::vector<Record>& shown() const { return shown_; }
    /// Their impact → visible times (ms).
    std::vector<double> visibleMs() const;
    /// Writes shown() as CSV (object, frame, adopted_ms, shown_ms, visible_ms); false when it cannot.
    bool writeCsv(const std::filesystem::path& path) const;

private:
    struct Pending {
        Record record;
        Clock::time_point at;
    };
    std::vector<Pending> pending_;
    std::vector<Record> shown_;
};

} // namespace demo
