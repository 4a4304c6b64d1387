#include "io/FileBytes.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

#include <sys/stat.h>

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
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        const int err = errno;
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot open: " +
                                                 (err ? std::strerror(err) : "unknown error"));
    }
    std::string bytes(static_cast<std::size_t>(st.st_size), '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (in.gcount() != static_cast<std::streamsize>(bytes.size()))
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot read the whole file");
    return bytes;
}

} // namespace rubble::io
