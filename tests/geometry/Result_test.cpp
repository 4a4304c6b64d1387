// Result, Status and the log hook: reading the value of a failed Result is a checked programming error that
// names the error; library messages go to the function set with setLogFunction, from any thread.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rubble/core/Log.hpp"
#include "rubble/core/Result.hpp"

using namespace rubble;

namespace {

Result<int> failing() {
    return makeError(ErrorCode::ParseError, "model.obj:17: face refers to vertex 9");
}

// Restores the default log function when a test ends.
struct LogGuard {
    ~LogGuard() { setLogFunction({}); }
};

} // namespace

TEST(Result, ValueAndErrorAccess) {
    Result<int> ok = 5;
    EXPECT_TRUE(ok);
    EXPECT_EQ(*ok, 5);
    EXPECT_EQ(ok.value(), 5);
    EXPECT_EQ(ok.error().code, ErrorCode::Ok) << "a successful result reports no error, like Status";
    EXPECT_TRUE(ok.error().message.empty());
    const Result<int> bad = failing();
    EXPECT_FALSE(bad);
    EXPECT_EQ(bad.error().code, ErrorCode::ParseError);
    EXPECT_FALSE(bad.status());
    EXPECT_EQ(bad.status().message(), "model.obj:17: face refers to vertex 9");
}

TEST(ResultDeathTest, ReadingTheValueOfAnErrorAbortsWithItsMessage) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_DEATH((void)*failing(),
                 "Result::value\\(\\) called on a failed Result: parse error: model.obj:17");
    EXPECT_DEATH((void)failing().value(), "parse error: model.obj:17");
    const Result<std::string> bad = makeError(ErrorCode::IoError, "cannot open x.obj");
    EXPECT_DEATH((void)bad->size(), "io error: cannot open x.obj");
}

TEST(Log, MessagesGoToTheLogFunctionFromAnyThread) {
    LogGuard guard;
    std::mutex mutex;
    std::vector<std::string> seen;
    setLogFunction([&](LogLevel level, std::string_view message) {
        const std::lock_guard lock(mutex);
        seen.push_back(std::string(toString(level)) + ": " + std::string(message));
    });
    logMessage(LogLevel::Warning, "mesh was repaired");
    std::thread worker([] { logMessage(LogLevel::Info, "from a worker"); });
    worker.join();
    ASSERT_EQ(seen.size(), 2u);
    EXPECT_EQ(seen[0], "warning: mesh was repaired");
    EXPECT_EQ(seen[1], "info: from a worker");
}

TEST(Log, AnEmptyFunctionRestoresTheDefaultAndANoOpSilences) {
    LogGuard guard;
    std::atomic<int> calls = 0;
    setLogFunction([&](LogLevel, std::string_view) { ++calls; });
    logMessage(LogLevel::Warning, "counted");
    setLogFunction([](LogLevel, std::string_view) {});
    logMessage(LogLevel::Warning, "silenced");
    EXPECT_EQ(calls, 1);
    setLogFunction({});
    testing::internal::CaptureStderr();
    logMessage(LogLevel::Warning, "to stderr");
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "rubble: warning: to stderr\n");
    EXPECT_EQ(calls, 1);
}

TEST(LogDeathTest, TheFailedValueMessageGoesThroughTheLogFunction) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_DEATH(
        {
            setLogFunction([](LogLevel level, std::string_view message) {
                std::fprintf(stderr, "hooked %s: %.*s\n", toString(level), static_cast<int>(message.size()),
                             message.data());
            });
            (void)*failing();
        },
        "hooked error: Result::value\\(\\) called on a failed Result");
}
