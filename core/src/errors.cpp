#include "soupuv/errors.h"

namespace soupuv {

const char* to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::invalid_input: return "invalid_input";
    case ErrorCode::unsupported: return "unsupported";
    case ErrorCode::limit_exceeded: return "limit_exceeded";
    case ErrorCode::no_triangles: return "no_triangles";
    case ErrorCode::canceled: return "canceled";
    case ErrorCode::not_built: return "not_built";
    case ErrorCode::internal: return "internal";
  }
  return "internal";
}

}  // namespace soupuv
