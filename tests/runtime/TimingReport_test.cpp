#include "rubble/TimingReport.hpp"

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

} // namespace
} // namespace rubble
