#include "core/result.h"

namespace wrap {

std::string_view ToString(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidInput:
      return "invalid input";
    case ErrorCode::kIo:
      return "i/o error";
    case ErrorCode::kInfeasible:
      return "infeasible";
    case ErrorCode::kTimeout:
      return "timeout";
    case ErrorCode::kCancelled:
      return "cancelled";
    case ErrorCode::kInternal:
      return "internal error";
  }
  return "unknown";
}

int ExitCodeFor(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidInput:
    case ErrorCode::kIo:
      return 2;
    case ErrorCode::kInfeasible:
    case ErrorCode::kTimeout:
    case ErrorCode::kCancelled:
      return 1;
    case ErrorCode::kInternal:
      return 3;
  }
  return 3;
}

}  // namespace wrap
