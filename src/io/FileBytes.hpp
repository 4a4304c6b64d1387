#pragma once
// Private helpers of the io module: reading a whole file with a clear error.

#include <filesystem>
#include <string>

#include "rubble/Result.hpp"

namespace rubble::io {

/// The whole content of a file, or an IoError naming it ("<file>: cannot open: <reason>").
Result<std::string> readFileBytes(const std::filesystem::path& path);

/// The name used for a path in messages (the path as given).
std::string displayName(const std::filesystem::path& path);

} // namespace rubble::io
