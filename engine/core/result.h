// Result and Error: how every engine stage reports an expected failure.
#pragma once

#include <expected>
#include <string>
#include <string_view>

namespace wrap {

/// What kind of failure an Error is. Each maps to one CLI exit code (DESIGN.md).
enum class ErrorCode {
  kInvalidInput,  ///< Bad user input: malformed file, wrong field, missing mesh. Exit 2.
  kIo,            ///< A file could not be read or written. Exit 2.
  kInfeasible,    ///< The problem has no solution under the given options. Exit 1.
  kTimeout,       ///< The deadline passed before a result was found. Exit 1.
  kCancelled,     ///< The run was cancelled through its stop token. Exit 1.
  kInternal,      ///< A bug or an unexpected third-party failure. Exit 3.
};

/// Short lower-case name of a code, e.g. "invalid input".
std::string_view ToString(ErrorCode code);

/// Process exit code for a failure of this kind: 1 no solution, 2 bad input, 3 internal.
int ExitCodeFor(ErrorCode code);

/// An expected failure: a code and a message naming the stage, the entity, what was seen and
/// what was expected.
struct Error {
  ErrorCode code = ErrorCode::kInternal;  ///< Kind of failure.
  std::string message;                    ///< Human-readable, one line, no trailing newline.
};

/// The value of a stage or the reason it has none.
template <typename T>
using Result = std::expected<T, Error>;

/// Shorthand for returning a failure: `return Fail(ErrorCode::kIo, "...")`.
inline std::unexpected<Error> Fail(ErrorCode code, std::string message) {
  return std::unexpected<Error>(Error{code, std::move(message)});
}

}  // namespace wrap
