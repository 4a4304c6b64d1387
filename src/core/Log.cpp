#include "rubble/core/Log.hpp"

#include <cstdio>
#include <memory>
#include <mutex>
#include <utility>

namespace rubble {

namespace {
void writeToStderr(LogLevel level, std::string_view message) {
    std::fprintf(stderr, "rubble: %s: %.*s\n", toString(level), static_cast<int>(message.size()),
                 message.data());
}

std::mutex logMutex;
std::shared_ptr<const LogFunction> logFunction; // null: writeToStderr
} // namespace

void setLogFunction(LogFunction function) {
    auto next = function ? std::make_shared<const LogFunction>(std::move(function)) : nullptr;
    const std::lock_guard lock(logMutex);
    logFunction = std::move(next);
}

void logMessage(LogLevel level, std::string_view message) {
    std::shared_ptr<const LogFunction> current;
    {
        const std::lock_guard lock(logMutex);
        current = logFunction;
    }
    if (current)
        (*current)(level, message);
    else
        writeToStderr(level, message);
}

const char* toString(LogLevel level) {
    switch (level) {
    case LogLevel::Info:
        return "info";
    case LogLevel::Warning:
        return "warning";
    case LogLevel::Error:
        return "error";
    }
    return "unknown";
}

} // namespace rubble
