#include "rubble/runtime/TimingReport.hpp"

#include <gtest/gtest.h>

namespace rubble {
namespace {

TEST(TimingReport, PercentilesAndStale) {
    std::vector<TimingRecord> r(100);
    for (int i = 0; i < 100; ++i)
        r[static_cast<std::size_t>(i)].totalMs = i + 1;
    TimingRecord st;
    st.stale = true;
    st.totalMs = 1e6;
    r.push_back(st);
    TimingRecord failed;
    failed.failed = true;
    failed.totalMs = 2e6;
    r.push_back(failed);
    TimingRecord missed;
    missed.missed = true;
    missed.totalMs = 3e6;
    r.push_back(missed);
    r.push_back(missed);
    const auto s = summarizeTimings(r);
    EXPECT_EQ(s.records, 100);
    EXPECT_EQ(s.stale, 1);
    EXPECT_EQ(s.failed, 1);
    EXPECT_EQ(s.missed, 2);
    EXPECT_DOUBLE_EQ(s.total.p50, 50);
    EXPECT_DOUBLE_EQ(s.total.p99, 99);
    EXPECT_DOUBLE_EQ(s.total.max, 100);
    EXPECT_NE(formatTimingSummary(s).find("total"), std::string::npos);
    EXPECT_NE(formatTimingSummary(s).find("100 records, 1 stale, 2 missed, 1 failed"), std::string::npos);
    EXPECT_EQ(summarizeTimings({}).records, 0);
}

TEST(TimingReport, EachStageIsSummarisedFromItsOwnField) {
    std::vector<TimingRecord> r(9);
    for (std::size_t i = 0; i < r.size(); ++i) {
        const double x = static_cast<double>(i + 1); // 1..9: the median is 5
        r[i] = {.queueMs = x,
                .prepareMs = 10 * x,
                .cellMs = 100 * x,
                .booleanMs = 1e3 * x,
                .islandsMs = 1e4 * x,
                .decompositionMs = 1e5 * x,
                .finishMs = 1e6 * x,
                .handoffMs = 1e7 * x,
                .adoptionMs = 1e8 * x,
                .totalMs = 1e9 * x};
    }
    const auto s = summarizeTimings(r);
    EXPECT_DOUBLE_EQ(s.queue.p50, 5);
    EXPECT_DOUBLE_EQ(s.prepare.p50, 50);
    EXPECT_DOUBLE_EQ(s.cell.p50, 500);
    EXPECT_DOUBLE_EQ(s.boolean.p50, 5e3);
    EXPECT_DOUBLE_EQ(s.islands.p50, 5e4);
    EXPECT_DOUBLE_EQ(s.decomposition.p50, 5e5);
    EXPECT_DOUBLE_EQ(s.finish.p50, 5e6);
    EXPECT_DOUBLE_EQ(s.handoff.p50, 5e7);
    EXPECT_DOUBLE_EQ(s.adoption.p50, 5e8);
    EXPECT_DOUBLE_EQ(s.total.p50, 5e9);
    EXPECT_DOUBLE_EQ(s.handoff.max, 9e7);
    const std::string text = formatTimingSummary(s);
    for (const char* stage : {"queue", "prepare", "cell", "boolean", "islands", "decomposition", "finish",
                              "handoff", "adoption", "total"})
        EXPECT_NE(text.find(stage), std::string::npos) << stage;
}

} // namespace
} // namespace rubble
