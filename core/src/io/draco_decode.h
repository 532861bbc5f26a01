// Draco mesh decoding on a checked byte range (KHR_draco_mesh_compression
// payloads and raw .drc files).
//
// Input : the compressed bytes (already bounds-checked by the caller), the
//         Draco unique id of the POSITION attribute (-1: the named POSITION
//         attribute, for raw .drc), and a triangle cap.
// Output: positions (one per Draco point, float values as double) and
//         triangles indexing them. Errors: invalid_input (undecodable, no
//         POSITION, indices out of range), no_triangles (a point cloud),
//         limit_exceeded (too many faces, or the decoder's CPU budget used up).
//
// Draco 1.5.5 (Debian) has decode loops bounded only by counts read from the
// stream, so a tiny hostile payload can spin for tens of seconds. The decoder
// therefore runs in a forked child under RLIMIT_CPU (2 s + 1 s per 50 kB of
// payload) and sends the mesh back through a pipe; the parent checks the
// answer again. POSIX-only; the caller's process must tolerate fork().
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::io::detail {

struct DracoMesh {
  std::vector<Vec3> positions;
  std::vector<Tri> triangles;
};

// True when the bytes start with Draco's "DRACO" magic.
bool has_draco_magic(std::span<const uint8_t> bytes);

DracoMesh decode_draco(std::span<const uint8_t> bytes, int64_t position_attribute_id,
                       uint64_t max_triangles, const std::string& where);

}  // namespace soupuv::io::detail
