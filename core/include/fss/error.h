#pragma once
/// \file error.h
/// Exceptions thrown by FSS. Every `what()` is one complete sentence meant for a person: it names the
/// file, parameter or mesh element at fault and the problem.

#include <stdexcept>
#include <string>
#include <utility>

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

/// An option outside its documented range, thrown by the options' validate() (StitchOptions, ScanParams,
/// FishboneParams, CurvatureOptions, AutoOptions, ...). what() is one sentence naming the struct, the field
/// and its range: "StitchOptions::minAngleFloorDeg must be in [0, 30), not 45."; the parts are kept so that
/// a caller can name the field its own way (the session-file reader names the JSON field).
class InvalidOptionError : public InvalidInputError {
public:
    /// \p owner "StitchOptions", \p field "minAngleFloorDeg" (a path for nested options:
    /// "tracing.backboneTracing.step"), \p requirement "must be in [0, 30), not 45" (no final period).
    InvalidOptionError(std::string owner, std::string field, std::string requirement)
        : InvalidInputError(owner + "::" + field + " " + requirement + "."), owner_(std::move(owner)),
          field_(std::move(field)), requirement_(std::move(requirement)) {}
    const std::string& owner() const noexcept { return owner_; }
    const std::string& field() const noexcept { return field_; }
    const std::string& requirement() const noexcept { return requirement_; }

private:
    std::string owner_, field_, requirement_;
};

/// The user cancelled a long operation through its Progress callback; nothing was changed.
class CancelledError : public Error {
public:
    CancelledError() : Error("The operation was cancelled.") {}
};

} // namespace fss
