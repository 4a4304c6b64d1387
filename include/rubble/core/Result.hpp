#pragma once
/// \file Result.hpp
/// Errors as data: no exception crosses Rubble's API. Functions that can fail return Result<T> or Status.
/// Both are [[nodiscard]]: an ignored error is a compile warning. Reading the value of a failed Result is a
/// programming error: it logs the error (see Log.hpp) and aborts.

#include <cassert>
#include <string>
#include <utility>
#include <variant>

#include "rubble/core/Export.hpp"

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
RUBBLE_API const char* toString(ErrorCode code);

/// An error: a code and a message that names what is wrong (file, line, field where known).
struct RUBBLE_API Error {
    ErrorCode code = ErrorCode::Ok; ///< the kind of failure
    std::string message;            ///< what went wrong, for people
};

/// Success or an Error, for functions without a value.
class [[nodiscard]] RUBBLE_API Status {
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

namespace detail {
/// Logs "Result::value() called on a failed Result: <code>: <message>" as an error and aborts.
[[noreturn]] RUBBLE_API void failedValueAccess(const Error& error);
/// The Error of every successful Result (code Ok, no message).
RUBBLE_API const Error& noError();
} // namespace detail

/// A value of type T or an Error.
template <class T>
class [[nodiscard]] Result {
public:
    /// A successful result holding value.
    Result(T value) : v_(std::move(value)) {}
    /// A failed result holding err.
    Result(Error err) : v_(std::move(err)) { assert(std::get<Error>(v_).code != ErrorCode::Ok); }
    /// True when a value is present.
    bool isOk() const { return std::holds_alternative<T>(v_); }
    /// True when a value is present.
    explicit operator bool() const { return isOk(); }
    /// The value; aborts with the error's message when !isOk().
    T& value() & { return checked(); }
    /// The value; aborts with the error's message when !isOk().
    const T& value() const& { return checked(); }
    /// The value moved out; aborts with the error's message when !isOk().
    T&& value() && { return std::move(checked()); }
    /// The value; aborts with the error's message when !isOk().
    T& operator*() & { return checked(); }
    /// The value; aborts with the error's message when !isOk().
    const T& operator*() const& { return checked(); }
    /// The value moved out; aborts with the error's message when !isOk().
    T&& operator*() && { return std::move(checked()); }
    /// Pointer-like access to the value; aborts with the error's message when !isOk().
    T* operator->() { return &checked(); }
    /// Pointer-like access to the value; aborts with the error's message when !isOk().
    const T* operator->() const { return &checked(); }
    /// The error (code Ok when successful, like Status::error()).
    const Error& error() const {
        const Error* e = std::get_if<Error>(&v_);
        return e ? *e : detail::noError();
    }
    /// The status of this result.
    Status status() const { return isOk() ? Status() : Status(error()); }

private:
    T& checked() {
        if (T* v = std::get_if<T>(&v_))
            return *v;
        detail::failedValueAccess(std::get<Error>(v_));
    }
    const T& checked() const {
        if (const T* v = std::get_if<T>(&v_))
            return *v;
        detail::failedValueAccess(std::get<Error>(v_));
    }

    std::variant<T, Error> v_;
};

/// Shorthand for building an Error.
inline Error makeError(ErrorCode code, std::string message) {
    return Error{code, std::move(message)};
}

} // namespace rubble
