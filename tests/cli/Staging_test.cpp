#include "Staging.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include <sys/wait.h>
#include <unistd.h>

#include "TestSupport.hpp"

using namespace rubble;

namespace {
// The PID of a child process that has exited (and been reaped): a process that no longer exists.
pid_t deadPid() {
    const pid_t child = ::fork();
    if (child == 0)
        ::_exit(0);
    int status = 0;
    ::waitpid(child, &status, 0);
    return child;
}
} // namespace

TEST(Staging, StagingPathIsAHiddenSiblingNamedAfterThisProcess) {
    EXPECT_EQ(tools::stagingPath("out/pieces"), "out/.pieces.rubble-tmp-" + std::to_string(::getpid()));
    EXPECT_EQ(tools::stagingPath("x.obj"), ".x.obj.rubble-tmp-" + std::to_string(::getpid()));
}

TEST(Staging, StaleEntriesOfDeadProcessesAreRemovedOthersKept) {
    // A kill during a write left ".out.rubble-tmp-PID/" behind, and later runs never cleaned it.
    const auto dir = test::tempDir("Staging_stale");
    const std::string dead = std::to_string(deadPid());
    std::filesystem::create_directories(dir / (".out.rubble-tmp-" + dead) / "sub");
    test::writeFile(dir / (".out.rubble-tmp-" + dead) / "sub" / "piece_000.obj", "v 0 0 0\n");
    test::writeFile(dir / (".x.obj.rubble-tmp-" + dead), "partial");
    test::writeFile(dir / (".y.obj.rubble-tmp-" + dead + ".3"), "partial"); // a file of writeFileAtomically
    const std::vector<std::string> kept = {".out.rubble-tmp-" + std::to_string(::getppid()), // alive
                                           ".out.rubble-tmp-" + std::to_string(::getpid()),  // this process
                                           ".out.rubble-tmp-abc",
                                           "out.rubble-tmp-" + dead,
                                           ".rubble-tmp-" + dead,
                                           ".z.obj.rubble-tmp-" + dead + ".x",
                                           "model.obj"};
    for (const std::string& k : kept)
        test::writeFile(dir / k, "keep");
    EXPECT_EQ(tools::removeStaleStaging(dir), 3u);
    std::set<std::string> left;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        left.insert(e.path().filename().string());
    EXPECT_EQ(left, std::set<std::string>(kept.begin(), kept.end()));
    EXPECT_EQ(tools::removeStaleStaging(dir / "missing"), 0u);
}

TEST(Staging, SignalsWaitUntilTheOutputIsCleanedUp) {
    // SIGTERM arriving while an output is staged ends the process only after the staging entry is gone.
    const auto dir = test::tempDir("Staging_signal");
    const auto stage = dir / ".out.rubble-tmp-child";
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        {
            const tools::DeferSignals deferred;
            test::writeFile(stage, "partial");
            ::kill(::getpid(), SIGTERM);
            ::kill(::getpid(), SIGINT);
            std::filesystem::remove(stage); // the cleanup still runs
            test::writeFile(dir / "cleaned", "");
        }
        ::_exit(0); // not reached: the pending signal ends the process here
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child exited normally: the signal was lost";
    EXPECT_TRUE(WTERMSIG(status) == SIGTERM || WTERMSIG(status) == SIGINT) << WTERMSIG(status);
    EXPECT_FALSE(std::filesystem::exists(stage));
    EXPECT_TRUE(std::filesystem::exists(dir / "cleaned"));
}
