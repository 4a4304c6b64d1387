#include "io/FileBytes.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace rubble::io {

std::string displayName(const std::filesystem::path& path) {
    return path.string();
}

Result<std::string> readFileBytes(const std::filesystem::path& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot read: is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        const int err = errno;
        return makeError(ErrorCode::IoError, displayName(path) + ": cannot open: " +
                                                 (err ? std::strerror(err) : "unknown error"));
    }
    std::string bytes;
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size > 0) {
        bytes.resize(static_cast<std::size_t>(size));
        in.seekg(0, std::ios::beg);
        in.read(bytes.data(), size);
        if (in.gcount() != size)
            return makeError(ErrorCode::IoError, displayName(path) + ": cannot read the whole file");
    } else {
        // Not seekable (a pipe) or empty: read what there is.
        in.clear();
        in.seekg(0, std::ios::beg);
        bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    return bytes;
}

} // namespace rubble::io
