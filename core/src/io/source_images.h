// The source materials' base-colour images, read while loading so that the
// re-bake (soupuv/bake/rebake.h) can sample them through the old UVs.
//
// Input : the document, its BufferTable (GLB bufferViews, data: URIs and
//         files beside a .gltf when allowed).
// Output: Asset::base_color_images by material index. An image that cannot be
//         read (external files off, missing, not PNG/JPEG) is a warning, never
//         an error: the geometry still maps, only the re-bake lacks it.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/buffer_table.h"
#include "soupuv/io/asset.h"

namespace soupuv::io::detail {

void read_base_color_images(const nlohmann::json& doc, BufferTable& buffers, Asset& asset,
                            std::vector<std::string>& warnings);

}  // namespace soupuv::io::detail
