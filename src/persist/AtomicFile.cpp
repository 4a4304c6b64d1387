#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>

#include "io/FileBytes.hpp"
#include "rubble/persist/JournalFile.hpp"

namespace rubble {
namespace {

Error ioError(const std::filesystem::path& path, const std::string& what) {
    return Error{ErrorCode::IoError, path.string() + ": " + what + ": " + std::strerror(errno)};
}

} // namespace

Status writeFileAtomic(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
    // One temporary file per call (process id and a counter): threads writing one path must not share it.
    static std::atomic<std::uint64_t> calls{0};
    const std::filesystem::path tmp =
        dir / (path.filename().string() + ".tmp." + std::to_string(static_cast<long>(::getpid())) + "." +
               std::to_string(calls.fetch_add(1, std::memory_order_relaxed)));
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        return ioError(tmp, "cannot create");
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            Error e = ioError(tmp, "write failed");
            ::close(fd);
            ::unlink(tmp.c_str());
            return e;
        }
        done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0) {
        Error e = ioError(tmp, "fsync failed");
        ::close(fd);
        ::unlink(tmp.c_str());
        return e;
    }
    ::close(fd);
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        Error e = ioError(path, "cannot rename " + tmp.string() + " to it");
        ::unlink(tmp.c_str());
        return e;
    }
    // The rename itself is durable once the folder is synced.
    if (const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
        (void)::fsync(dfd);
        ::close(dfd);
    }
    return Status::ok();
}

Result<std::vector<std::uint8_t>> readFileBinary(const std::filesystem::path& path) {
    // Regular files only, as the mesh readers: a device never ends and a FIFO blocks.
    Result<std::string> bytes = io::readFileBytes(path);
    if (!bytes)
        return bytes.error();
    return std::vector<std::uint8_t>(bytes->begin(), bytes->end());
}

} // namespace rubble
