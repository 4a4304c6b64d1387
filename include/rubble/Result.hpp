#pragma once
/// \file Result.hpp
/// Errors as data: no exception crosses Rubble's API. Functions that can fail return Result<T> or Status.

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace rubble {

/// What kind of failure an Error is.
enum class ErrorCode {
    Ok = 0,          ///< no error
    IoError,         ///< a file could not be opened, read or written
    ParseError,      ///< a file was read but its content is malformed
    InvalidInput,    ///< an argument or mesh violates a precondition (e.g. open mesh, NaN coordinate)
    Unsupported,     ///< a format or feature that is not available
    NoIntersection,  ///< an operation had nothing to act on (e.g. an impact outside the mesh)
    GeometryFailure, ///< a geometric kernel failed on this input; the input is left unchanged
    Cancelled,       ///< the operation was cancelled or superseded
};

/// Human-readable name of an error code.
const char* toString(ErrorCode code);

/// An error: a code and a message that names what is wrong (file, line, field where known).
struct Error {
    ErrorCode code = ErrorCode::Ok; ///< the kind of failure
    std::string message;            ///< what went wrong, for people
};

/// Success or an Error, for functions without a value.
class Status {
public:
    /// A successful status.
    Status() = default;
    /// A failed status carrying err.
    Status(Error err) : error_(std::move(err)) {}
    /// A successful status.
    static Status ok() { return {}; }
    /// True when no error occurred.
    bool isOk() const { return error_.code == ErrorCode::Ok; }
    /// True when no error occurred.
    explicit operator bool() const { return isOk(); }
    /// The error (code Ok when successful).
    const Error& error() const { return error_; }
    /// The error message (empty when successful).
    const std::string& message() const { return error_.message; }

private:
    Error error_;
};

/// A value of type T or an Error.
template <class T>
class Result {
public:
    /// A successful result holding value.
    Result(T value) : v_(std::move(value)) {}
    /// A failed result holding err.
    Result(Error err) : v_(std::move(err)) { assert(std::get<Error>(v_).code != ErrorCode::Ok); }
    /// True when a value is present.
    bool isOk() const { return std::holds_alternative<T>(v_); }
    /// True when a value is present.
    explicit operator bool() const { return isOk(); }
    /// The value; only valid when isOk().
    T& value() & { return std::get<T>(v_); }
    /// The value; only valid when isOk().
    const T& value() const& { return std::get<T>(v_); }
    /// The value moved out; only valid when isOk().
    T&& value() && { return std::get<T>(std::move(v_)); }
    /// The value; only valid when isOk().
    T& operator*() & { return std::get<T>(v_); }
    /// The value; only valid when isOk().
    const T& operator*() const& { return std::get<T>(v_); }
    /// Pointer-like access to the value.
    T* operator->() { return &std::get<T>(v_); }
    /// Pointer-like access to the value.
    const T* operator->() const { return &std::get<T>(v_); }
    /// The error; only valid when !isOk().
    const Error& error() const { return std::get<Error>(v_); }
    /// The status of this result.
    Status status() const { return isOk() ? Status() : Status(error()); }

private:
    std::variant<T, Error> v_;
};

/// Shorthand for building an Error.
inline Error makeError(ErrorCode code, std::string message) {
    return Error{code, std::move(message)};
}

} // namespace rubble
