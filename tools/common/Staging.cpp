#include "Staging.hpp"

#include <cerrno>
#include <charconv>
#include <cstdint>
#include <string>
#include <vector>

#include <signal.h>
#include <unistd.h>

namespace rubble::tools {

namespace {
sigset_t heldSignals() {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGHUP);
    return set;
}

constexpr std::string_view kMarker = ".rubble-tmp-";
} // namespace

DeferSignals::DeferSignals() {
    const sigset_t set = heldSignals();
    pthread_sigmask(SIG_BLOCK, &set, &previous_);
}

DeferSignals::~DeferSignals() {
    pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
}

std::filesystem::path stagingPath(const std::filesystem::path& target) {
    return target.parent_path() /
           ("." + target.filename().string() + std::string(kMarker) + std::to_string(::getpid()));
}

std::size_t removeStaleStaging(const std::filesystem::path& folder) {
    std::error_code ec;
    std::vector<std::filesystem::path> stale;
    for (std::filesystem::directory_iterator it(folder.empty() ? "." : folder, ec), end; !ec && it != end;
         it.increment(ec)) {
        const std::string name = it->path().filename().string();
        const std::size_t at = name.rfind(kMarker);
        if (name.size() < 2 || name[0] != '.' || at == std::string::npos || at == 0)
            continue;
        const char* first = name.data() + at + kMarker.size();
        const char* last = name.data() + name.size();
        long pid = 0;
        auto [ptr, err] = std::from_chars(first, last, pid);
        if (err == std::errc() && ptr != last && *ptr == '.') { // ".PID.N": a file of writeFileAtomically
            std::uint64_t call = 0;
            const char* after = ptr + 1;
            const std::from_chars_result r = std::from_chars(after, last, call);
            ptr = r.ptr;
            err = r.ec;
            if (ptr == after)
                continue;
        }
        if (err != std::errc() || ptr != last || first == last || pid <= 0 || pid == ::getpid())
            continue;
        if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH)
            continue; // alive (or not ours to signal): in use
        stale.push_back(it->path());
    }
    std::size_t removed = 0;
    for (const auto& p : stale)
        if (std::filesystem::remove_all(p, ec) > 0 && !ec)
            ++removed;
    return removed;
}

} // namespace rubble::tools
