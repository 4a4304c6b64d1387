#pragma once
/// \file Log.hpp
/// The library's only output channel: warnings and errors go to a log function the application sets
/// (default: one line on stderr). Rubble never writes to stdout or stderr itself.

#include <functional>
#include <string_view>

#include "rubble/core/Export.hpp"

namespace rubble {

/// How serious a log message is.
enum class LogLevel {
    Info,    ///< something worth knowing (e.g. a fallback was taken)
    Warning, ///< the library worked around a problem (e.g. repaired a mesh, made an object indestructible)
    Error,   ///< a programming error the library is about to abort on
};

/// Receives every log message; may be called from worker threads, so it must be thread-safe.
using LogFunction = std::function<void(LogLevel level, std::string_view message)>;

/// Replaces the log function (thread-safe). An empty function restores the default, which writes
/// "rubble: <level>: <message>" lines to stderr; to silence the library pass a function that does nothing.
RUBBLE_API void setLogFunction(LogFunction function);

/// Sends a message to the current log function.
RUBBLE_API void logMessage(LogLevel level, std::string_view message);

/// Lower-case name of a level ("info", "warning", "error").
RUBBLE_API const char* toString(LogLevel level);

} // namespace rubble
