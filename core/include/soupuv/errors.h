// The one exception type the core throws. The CLI prints message() and exits
// non-zero; the server maps code() to an HTTP status in one table.
#pragma once

#include <stdexcept>
#include <string>

namespace soupuv {

enum class ErrorCode {
  invalid_input,   // malformed file, bad numbers, out-of-range indices
  unsupported,     // valid but outside what soupuv handles (e.g. required extension)
  limit_exceeded,  // bigger than a configured triangle or byte limit
  no_triangles,    // nothing to map
  canceled,        // the caller's cancel token was set
  not_built,       // a feature that is not implemented yet
  internal,        // a bug or an unexpected numerical failure
};

const char* to_string(ErrorCode code);

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

}  // namespace soupuv
