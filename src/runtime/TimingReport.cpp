#include "rubble/TimingReport.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rubble {
namespace {

StageSummary summarize(std::vector<double> v) {
    StageSummary s;
    if (v.empty())
        return s;
    std::sort(v.begin(), v.end());
    auto rank = [&](double q) {
        const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
        return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
    };
    s.p50 = rank(0.5);
    s.p99 = rank(0.99);
    s.max = v.back();
    return s;
}

} // namespace

TimingSummary summarizeTimings(const std::vector<TimingRecord>& records) {
    TimingSummary out;
    std::vector<double> q, c, b, i, d, a, t;
    for (const auto& r : records) {
        if (r.stale) {
            ++out.stale;
            continue;
        }
        if (r.missed) {
            ++out.missed;
            continue;
        }
        if (r.failed) {
            ++out.failed;
            continue;
        }
        ++out.records;
        q.push_back(r.queueMs);
        c.push_back(r.cellMs);
        b.push_back(r.booleanMs);
        i.push_back(r.islandsMs);
        d.push_back(r.decompositionMs);
        a.push_back(r.adoptionMs);
        t.push_back(r.totalMs);
    }
    out.queue = summarize(q);
    out.cell = summarize(c);
    out.boolean = summarize(b);
    out.islands = summarize(i);
    out.decomposition = summarize(d);
    out.adoption = summarize(a);
    out.total = summarize(t);
    return out;
}

std::string formatTimingSummary(const TimingSummary& s) {
    std::string out;
    char line[160];
    auto add = [&](const char* name, const StageSummary& st) {
        std::snprintf(line, sizeof line, "%-13s p50 %8.3f  p99 %8.3f  max %8.3f ms\n", name, st.p50, st.p99,
                      st.max);
        out += line;
    };
    std::snprintf(line, sizeof line, "%d records, %d stale, %d missed, %d failed\n", s.records, s.stale,
                  s.missed, s.failed);
    out += line;
    add("queue", s.queue);
    add("cell", s.cell);
    add("boolean", s.boolean);
    add("islands", s.islands);
    add("decomposition", s.decomposition);
    add("adoption", s.adoption);
    add("total", s.total);
    return out;
}

} // namespace rubble
