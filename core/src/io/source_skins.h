// The source skins' inverse bind matrices, read while loading: the writer
// keeps every skin (its joints, skeleton and these matrices) but no longer has
// the source buffers.
//
// Input : the document and its BufferTable.
// Output: one SourceSkin per entry of document["skins"]. A skin whose
//         inverseBindMatrices accessor cannot be read, is not MAT4 or holds
//         fewer matrices than the skin has joints is marked unreadable and
//         named in `warnings` (the writer then drops it); a broken skin never
//         stops the geometry from mapping. Byte limits still throw.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/buffer_table.h"
#include "soupuv/io/asset.h"

namespace soupuv::io::detail {

std::vector<SourceSkin> read_source_skins(const nlohmann::json& doc, BufferTable& buffers, uint64_t max_bytes,
                                          std::vector<std::string>& warnings);

}  // namespace soupuv::io::detail
