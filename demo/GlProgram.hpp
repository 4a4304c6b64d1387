#pragma once
/// \file GlProgram.hpp
/// Compiling and linking a vertex + fragment shader pair.

#include <string>

#include <epoxy/gl.h>

namespace demo {

/// The linked program of the two sources, or 0 with the compiler's or linker's log appended to error.
GLuint linkProgram(const char* vs, const char* fs, std::string& error);

} // namespace demo
