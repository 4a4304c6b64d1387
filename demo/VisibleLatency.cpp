#include "VisibleLatency.hpp"

#include <fstream>

namespace demo {

void VisibleLatency::adopted(std::uint64_t object, std::uint64_t frame, double adoptedMs,
                             Clock::time_point at) {
    pending_.push_back({{object, frame, adoptedMs, 0}, at});
}

void VisibleLatency::presented(Clock::time_point at) {
    for (Pending& p : pending_) {
        p.record.shownMs = std::chrono::duration<double, std::milli>(at - p.at).count();
        shown_.push_back(p.record);
    }
    pending_.clear();
}

void VisibleLatency::clear() {
    pending_.clear();
    shown_.clear();
}

std::vector<double> VisibleLatency::visibleMs() const {
    std::vector<double> out;
    out.reserve(shown_.size());
    for (const Record& r : shown_)
        out.push_back(r.visibleMs());
    return out;
}

bool VisibleLatency::writeCsv(const std::filesystem::path& path) const {
    std::ofstream f(path);
    f << "object,frame,adopted_ms,shown_ms,visible_ms\n";
    for (const Record& r : shown_)
        f << r.object << ',' << r.frame << ',' << r.adoptedMs << ',' << r.shownMs << ',' << r.visibleMs()
          << '\n';
    return static_cast<bool>(f);
}

} // namespace demo
