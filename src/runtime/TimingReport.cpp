#include "rubble/runtime/TimingReport.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <utility>

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
    // each stage of a record and where its summary goes
    const std::pair<double TimingRecord::*, StageSummary*> stages[] = {
        {&TimingRecord::queueMs, &out.queue},       {&TimingRecord::prepareMs, &out.prepare},
        {&TimingRecord::cellMs, &out.cell},         {&TimingRecord::booleanMs, &out.boolean},
        {&TimingRecord::islandsMs, &out.islands},   {&TimingRecord::decompositionMs, &out.decomposition},
        {&TimingRecord::finishMs, &out.finish},     {&TimingRecord::handoffMs, &out.handoff},
        {&TimingRecord::adoptionMs, &out.adoption}, {&TimingRecord::totalMs, &out.total}};
    std::vector<std::vector<double>> samples(std::size(stages));
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
        for (std::size_t k = 0; k < std::size(stages); ++k)
            samples[k].push_back(r.*stages[k].first);
    }
    for (std::size_t k = 0; k < std::size(stages); ++k)
        *stages[k].second = summarize(std::move(samples[k]));
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
    add("prepare", s.prepare);
    add("cell", s.cell);
    add("boolean", s.boolean);
    add("islands", s.islands);
    add("decomposition", s.decomposition);
    add("finish", s.finish);
    add("handoff", s.handoff);
    add("adoption", s.adoption);
    add("total", s.total);
    return out;
}

} // namespace rubble
