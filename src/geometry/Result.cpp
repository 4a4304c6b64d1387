#include "rubble/Result.hpp"

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
