#pragma once
// Private to the io module (and its fuzz target): Rubble's readers of PLY and STL bytes, as readMesh uses
// them.

#include <string>

#include "rubble/core/Result.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::io {

/// A PLY file's bytes, ASCII or binary; errors name displayName and the line (ASCII) or byte (binary).
Result<Mesh> parsePly(const std::string& bytes, const std::string& displayName);

/// An STL file's bytes, ASCII (starting with "solid", text only) or binary; errors name displayName.
Result<Mesh> parseStl(const std::string& bytes, const std::string& displayName);

} // namespace rubble::io
