#include "io/FileBytes.hpp"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace rubble::io {

std::string displayName(const std::filesystem::path& path) {
    return path.string();
}

namespace {
const char* fileKind(mode_t mode) {
    if (S_ISDIR(mode))
        return "a directory";
    if (S_ISCHR(mode))
        return "a character device";
    if (S_ISBLK(mode))
        return "a block device";
    if (S_ISFIFO(mode))
        return "a FIFO";
    if (S_ISSOCK(mode))
        return "a socket";
    return "not a regular file";
}
} // namespace

Result<std::string> readFileBytes(const std::filesystem::path& path, std::uint64_t maxBytes) {
    // Only regular files (after symbolic links): /dev/zero never ends and a FIFO blocks the open.
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        const int err = errno;
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot open: " + std::strerror(err));
    }
    if (S_ISDIR(st.st_mode))
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot read: is a directory");
    if (!S_ISREG(st.st_mode))
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot read: it is " +
                                                 fileKind(st.st_mode) + ", not a regular file");
    if (static_cast<std::uint64_t>(st.st_size) > maxBytes)
        return makeError(ErrorCode::IoError,
                         displayName(path) + ": the file has " + std::to_string(st.st_size) +
                             " bytes, more than the limit of " + std::to_string(maxBytes) + " bytes");
    // The size is that of the file opened: a writer may have renamed another file over path since the stat.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        const int err = errno;
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot open: " + std::strerror(err));
    }
    struct stat opened {};
    if (::fstat(fd, &opened) != 0 || !S_ISREG(opened.st_mode) ||
        static_cast<std::uint64_t>(opened.st_size) > maxBytes) {
        ::close(fd);
        return makeError(ErrorCode::IoError,
                         displayName(path) + ": cannot read: it changed while it was opened");
    }
    std::string bytes(static_cast<std::size_t>(opened.st_size), '\0');
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ::ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        done += static_cast<std::size_t>(n);
    }
    ::close(fd);
    if (done != bytes.size())
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot read the whole file");
    return bytes;
}

std::filesystem::path stagingPath(const std::filesystem::path& target) {
    const std::filesystem::path name = target.filename();
    return target.parent_path() / ("." + name.string() + ".rubble-tmp-" + std::to_string(::getpid()));
}

Status writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
    // One staging file per call: threads of one process writing the same path must not share it.
    static std::atomic<std::uint64_t> calls{0};
    std::filesystem::path tmp = stagingPath(path);
    tmp += "." + std::to_string(calls.fetch_add(1, std::memory_order_relaxed));
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) {
        const int err = errno;
        return makeError(ErrorCode::IoError,
                         displayName(path) + ": cannot open for writing: " + std::strerror(err));
    }
    int err = 0;
    for (std::size_t done = 0; done < bytes.size() && err == 0;) {
        const ::ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno != EINTR)
            err = errno;
        else if (n > 0)
            done += static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0 && err == 0)
        err = errno;
    if (err == 0 && ::rename(tmp.c_str(), path.c_str()) != 0)
        err = errno;
    if (err != 0) {
        ::unlink(tmp.c_str());
        return makeError(ErrorCode::IoError, displayName(path) + ": write failed: " + std::strerror(err));
    }
    return {};
}

} // namespace rubble::io
