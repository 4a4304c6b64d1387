#pragma once
/// \file TimingReport.hpp
/// Percentile summaries of DestructionWorld timing records (for the bench and the demo).

#include <string>
#include <vector>

#include "rubble/DestructionWorld.hpp"

namespace rubble {

/// p50 / p99 / max of one stage, in milliseconds.
struct StageSummary {
    double p50 = 0; ///< median
    double p99 = 0; ///< 99th percentile (nearest rank)
    double max = 0; ///< maximum
};

/// Summary of a set of timing records (stale and failed records are counted but excluded from the
/// statistics: these describe impacts that were adopted).
struct TimingSummary {
    int records = 0;            ///< non-stale records summarised
    int stale = 0;              ///< stale records
    int failed = 0;             ///< failed records
    StageSummary queue;         ///< TimingRecord::queueMs
    StageSummary cell;          ///< TimingRecord::cellMs
    StageSummary boolean;       ///< TimingRecord::booleanMs
    StageSummary islands;       ///< TimingRecord::islandsMs
    StageSummary decomposition; ///< TimingRecord::decompositionMs
    StageSummary adoption;      ///< TimingRecord::adoptionMs
    StageSummary total;         ///< TimingRecord::totalMs
};

/// Percentiles of every stage over the records.
TimingSummary summarizeTimings(const std::vector<TimingRecord>& records);

/// One line per stage ("total p50 1.23 p99 4.56 max 7.89 ms").
std::string formatTimingSummary(const TimingSummary& summary);

} // namespace rubble
