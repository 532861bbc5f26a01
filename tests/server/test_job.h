// A job as an upload leaves it for the store (fresh id, created now, one GLB
// input), for the tests that talk to a job store directly.
#pragma once

#include <cstdint>
#include <string>

#include "soupuv/server/files.h"
#include "soupuv/server/job.h"

namespace soupuv::test {

inline server::Job upload_job(const std::string& request_hash, int64_t input_bytes) {
  server::Job j;
  j.id = server::new_job_id();
  j.created_at = server::now_seconds();
  j.input_file = "input.glb";
  j.content_type = "model/gltf-binary";
  j.input_bytes = input_bytes;
  j.request_hash = request_hash;
  return j;
}

}  // namespace soupuv::test
