#pragma once
// Output staging of the CLI tools: a staging entry ".NAME.rubble-tmp-PID" (file or folder) next to the output
// is renamed to NAME when complete (the library's writers stage files the same way). SIGINT and SIGTERM are
// held back while an output is staged, and entries left by a process that was killed anyway are removed
// later.

#include <csignal>
#include <cstddef>
#include <filesystem>

namespace rubble::tools {

/// While alive, SIGINT, SIGTERM and SIGHUP stay pending in the calling thread; when destroyed they are
/// unblocked, so a signal that came in takes effect (by default: the process ends) only after the staged
/// output was renamed or removed.
class DeferSignals {
public:
    DeferSignals();
    ~DeferSignals();
    DeferSignals(const DeferSignals&) = delete;
    DeferSignals& operator=(const DeferSignals&) = delete;

private:
    sigset_t previous_;
};

/// This process's staging entry for target: target's folder / ".NAME.rubble-tmp-PID".
std::filesystem::path stagingPath(const std::filesystem::path& target);

/// Removes the staging entries in folder (".NAME.rubble-tmp-PID", files or folders) whose process no longer
/// exists; returns how many were removed. Entries of live processes and other files are left alone.
std::size_t removeStaleStaging(const std::filesystem::path& folder);

} // namespace rubble::tools
