#pragma once
// Private helpers of the io module: reading a whole file with a clear error.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "rubble/Result.hpp"

namespace rubble::io {

/// Largest file the readers accept (2 GiB): far above any mesh Rubble fractures, and a clear error instead of
/// running out of memory.
inline constexpr std::uint64_t kMaxFileBytes = std::uint64_t{1} << 31;

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
