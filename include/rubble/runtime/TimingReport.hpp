#pragma once
/// \file TimingReport.hpp
/// Percentile summaries of DestructionWorld timing records (for the bench and the demo).

#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble {

/// p50 / p99 / max of one stage, in milliseconds.
struct RUBBLE_API StageSummary {
    double p50 = 0; ///< median
    double p99 = 0; ///< 99th percentile (nearest rank)
    double max = 0; ///< maximum
};

/// Summary of a set of timing records. Stale, missed and failed records are counted but excluded from the
/// statistics: these describe jobs whose pieces were adopted, so total is the impact → adopted latency. A job
/// is timed from the submission of its first impact: impacts that waited on an earlier job for the same
/// object (merged, forwarded to a piece, or retried after a miss or failure) include that wait.
struct RUBBLE_API TimingSummary {
    int records = 0;            ///< adopted records summarised (neither stale, missed nor failed)
    int stale = 0;              ///< stale records (the object changed or went away meanwhile)
    int missed = 0;             ///< missed records (the cells did not intersect the mesh)
    int failed = 0;             ///< failed records (a geometry failure)
    StageSummary queue;         ///< TimingRecord::queueMs
    StageSummary prepare;       ///< TimingRecord::prepareMs
    StageSummary cell;          ///< TimingRecord::cellMs
    StageSummary boolean;       ///< TimingRecord::booleanMs
    StageSummary islands;       ///< TimingRecord::islandsMs
    StageSummary decomposition; ///< TimingRecord::decompositionMs
    StageSummary finish;        ///< TimingRecord::finishMs
    StageSummary handoff;       ///< TimingRecord::handoffMs
    StageSummary adoption;      ///< TimingRecord::adoptionMs
    StageSummary total;         ///< TimingRecord::totalMs
};

/// Percentiles of every stage over the records.
RUBBLE_API TimingSummary summarizeTimings(const std::vector<TimingRecord>& records);

/// A counts line ("12 records, 0 stale, 1 missed, 0 failed"), then one line per stage
/// ("total p50 1.23 p99 4.56 max 7.89 ms").
RUBBLE_API std::string formatTimingSummary(const TimingSummary& summary);

} // namespace rubble
