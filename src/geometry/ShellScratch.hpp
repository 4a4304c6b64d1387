#pragma once
// Private to the core: the work arrays that closedOrientedShells keeps per thread between calls.

#include <cstddef>

namespace rubble::detail {

/// Bytes of work arrays that the calling thread keeps.
std::size_t shellScratchBytes();
/// Frees the calling thread's kept work arrays of closedOrientedShells when they hold more than keepBytes.
void trimShellScratch(std::size_t keepBytes);

} // namespace rubble::detail
