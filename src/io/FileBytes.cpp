#include "io/FileBytes.hpp"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <optional>
#include <utility>

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

RegularFile& RegularFile::operator=(RegularFile&& o) noexcept {
    if (this != &o) {
        if (fd_ >= 0)
            ::close(fd_);
        fd_ = std::exchange(o.fd_, -1);
        size_ = o.size_;
    }
    return *this;
}

RegularFile::~RegularFile() {
    if (fd_ >= 0)
        ::close(fd_);
}

Result<RegularFile> openRegularFile(const std::filesystem::path& path, std::uint64_t maxBytes) {
    // Only regular files (after symbolic links): /dev/zero never ends and a FIFO blocks the open.
    auto refuse = [&](const struct stat& st) -> std::optional<Error> {
        if (S_ISDIR(st.st_mode))
            return Error{ErrorCode::IoError, displayName(path) + ": cannot read: is a directory"};
        if (!S_ISREG(st.st_mode))
            return Error{ErrorCode::IoError, displayName(path) + ": cannot read: it is " +
                                                 fileKind(st.st_mode) + ", not a regular file"};
        if (static_cast<std::uint64_t>(st.st_size) > maxBytes)
            return Error{ErrorCode::IoError,
                         displayName(path) + ": the file has " + std::to_string(st.st_size) +
                             " bytes, more than the limit of " + std::to_string(maxBytes) + " bytes"};
        return std::nullopt;
    };
    auto cannotOpen = [&](int err) {
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot open: " +
                                                 (err ? std::strerror(err) : "unknown error"));
    };
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0)
        return cannotOpen(errno);
    if (auto e = refuse(st))
        return *e;
    // Non-blocking, then checked again: the path may have been swapped for a FIFO since the stat.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0)
        return cannotOpen(errno);
    RegularFile file(fd, 0);
    if (::fstat(fd, &st) != 0)
        return cannotOpen(errno);
    if (auto e = refuse(st))
        return *e;
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0)
        return cannotOpen(errno);
    file.setSize(static_cast<std::uint64_t>(st.st_size));
    return file;
}

Result<std::string> readFileBytes(const std::filesystem::path& path, std::uint64_t maxBytes) {
    auto file = openRegularFile(path, maxBytes);
    if (!file)
        return file.error();
    std::string bytes(static_cast<std::size_t>(file->size()), '\0');
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ::ssize_t n = ::read(file->fd(), bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            const int err = errno;
            return makeError(ErrorCode::IoError, displayName(path) + ": cannot read: " + std::strerror(err));
        }
        if (n == 0)
            return makeError(ErrorCode::IoError, displayName(path) + ": cannot read the whole file");
        done += static_cast<std::size_t>(n);
    }
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
