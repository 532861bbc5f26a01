// The traced field lines: the field branch's result that the transfer stage
// intersects with the proxy. Contract between field/ and transfer/: keep these
// fields; add to them rather than change them.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::field {

enum class LineEnd : uint8_t {
  escaped = 0,     // left the bounding sphere (the normal end)
  step_limit = 1,  // ran out of steps
  stalled = 2,     // |E| vanished (e.g. inside a closed part)
  trapped = 3,     // crawled along the surface (TraceOptions::trapped_steps)
  reached = 4,     // its last step crossed TraceOptions::stop_crossing (the pipeline: the proxy)
};

struct FieldLines {
  // Line i is points[offsets[i] .. offsets[i+1]); offsets.size() == lines + 1.
  std::vector<Vec3> points;
  std::vector<uint32_t> offsets{0};
  std::vector<LineEnd> ends;     // one per line
  // Which soup corner each line starts at: triangle * 3 + corner.
  std::vector<uint32_t> corner;

  size_t size() const { return ends.size(); }
};

}  // namespace soupuv::field
