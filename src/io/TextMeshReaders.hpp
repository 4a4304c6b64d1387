#pragma once
// Private to the io module (and its fuzz target): Rubble's readers of ASCII PLY and ASCII STL text, as
// readMesh uses them after its checks of the file.

#include <string>

#include "rubble/Mesh.hpp"
#include "rubble/Result.hpp"

namespace rubble::io {

/// A PLY file's bytes: the header is checked; an ASCII body is read exactly, a binary one is Unsupported
/// here.
Result<Mesh> parseAsciiPly(const std::string& bytes, const std::string& displayName);

/// An ASCII STL file's bytes (starting with "solid"); errors name displayName and the line.
Result<Mesh> parseAsciiStl(const std::string& bytes, const std::string& displayName);

} // namespace rubble::io
