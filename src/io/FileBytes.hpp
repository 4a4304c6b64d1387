#pragma once
// Private helpers of the io module: reading a whole file with a clear error.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "rubble/core/Result.hpp"

namespace rubble::io {

/// Largest file the readers accept (2 GiB): far above any mesh Rubble fractures, and a clear error instead of
/// running out of memory.
inline constexpr std::uint64_t kMaxFileBytes = std::uint64_t{1} << 31;

/// A read-only descriptor of a regular file, closed when destroyed.
class RegularFile {
public:
    RegularFile(int fd, std::uint64_t size) : fd_(fd), size_(size) {}
    RegularFile(RegularFile&& o) noexcept : fd_(o.fd_), size_(o.size_) { o.fd_ = -1; }
    RegularFile& operator=(RegularFile&& o) noexcept;
    RegularFile(const RegularFile&) = delete;
    RegularFile& operator=(const RegularFile&) = delete;
    ~RegularFile();
    /// The descriptor (blocking reads).
    int fd() const { return fd_; }
    /// The file's size when it was opened.
    std::uint64_t size() const { return size_; }
    /// Records the size (from fstat).
    void setSize(std::uint64_t size) { size_ = size; }

private:
    int fd_ = -1;
    std::uint64_t size_ = 0;
};

/// The file opened for reading when it is a regular file (after symbolic links) of at most maxBytes, or an
/// IoError naming it ("<file>: cannot open: <reason>", "<file>: cannot read: it is a FIFO, not a regular
/// file", "<file>: the file has N bytes, more than the limit of M bytes"). Devices, FIFOs and sockets are
/// refused without being opened, and a file swapped for one meanwhile is refused without blocking.
Result<RegularFile> openRegularFile(const std::filesystem::path& path,
                                    std::uint64_t maxBytes = kMaxFileBytes);

/// The whole content of a regular file of at most maxBytes, or an IoError naming it ("<file>: cannot open:
/// <reason>", "<file>: cannot read: it is a FIFO, not a regular file", "<file>: the file has N bytes, more
/// than the limit of M bytes"). Devices, FIFOs and sockets are refused without being opened.
Result<std::string> readFileBytes(const std::filesystem::path& path, std::uint64_t maxBytes = kMaxFileBytes);

/// Where this process stages a file or folder before renaming it to target: ".NAME.rubble-tmp-PID" next to
/// it. A staging entry whose process is gone was left by a kill; the CLI removes such entries.
std::filesystem::path stagingPath(const std::filesystem::path& target);

/// Writes bytes to a staging file next to path (stagingPath plus ".N", one per call, so that threads writing
/// one path do not share it) and renames it to path: path is either left as it was or holds all of bytes.
/// Errors (IoError) name path and the reason ("<file>: write failed: No space left on device").
Status writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

/// The name used for a path in messages (the path as given).
std::string displayName(const std::filesystem::path& path);

} // namespace rubble::io
