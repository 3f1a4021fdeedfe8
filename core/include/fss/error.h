#pragma once
/// \file error.h
/// Exceptions thrown by FSS. Every `what()` is one complete sentence meant for a person: it names the
/// file, parameter or mesh element at fault and the problem.

#include <stdexcept>
#include <string>

namespace fss {

/// Base of all FSS errors.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A file could not be read or written (missing, empty, truncated, unknown format, garbage, ...).
class IoError : public Error {
public:
    using Error::Error;
};

/// A parameter or a mesh violates a documented precondition (absurd resolution, NaN, empty view, ...).
class InvalidInputError : public Error {
public:
    using Error::Error;
};

/// The user cancelled a long operation through its Progress callback; nothing was changed.
class CancelledError : public Error {
public:
    CancelledError() : Error("The operation was cancelled.") {}
};

} // namespace fss
