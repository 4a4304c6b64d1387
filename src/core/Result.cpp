#include "rubble/core/Result.hpp"

#include <cstdlib>
#include <string>

#include "rubble/core/Log.hpp"

namespace rubble {

const char* toString(ErrorCode code) {
    switch (code) {
    case ErrorCode::Ok:
        return "ok";
    case ErrorCode::IoError:
        return "io error";
    case ErrorCode::ParseError:
        return "parse error";
    case ErrorCode::InvalidInput:
        return "invalid input";
    case ErrorCode::Unsupported:
        return "unsupported";
    case ErrorCode::NoIntersection:
        return "no intersection";
    case ErrorCode::GeometryFailure:
        return "geometry failure";
    case ErrorCode::Cancelled:
        return "cancelled";
    }
    return "unknown";
}

} // namespace rubble

namespace rubble::detail {

void failedValueAccess(const Error& error) {
    logMessage(LogLevel::Error, std::string("Result::value() called on a failed Result: ") +
                                    toString(error.code) + ": " + error.message);
    std::abort();
}

const Error& noError() {
    static const Error none;
    return none;
}

} // namespace rubble::detail
