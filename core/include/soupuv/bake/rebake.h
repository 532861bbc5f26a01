// Re-bake: the input's base colour carried onto the new map, so the model
// looks as it did with its new continuous UVs.
//
// Why it works: the output triangles are the input's, in the same order, so a
// texel inside triangle t's new-UV image has barycentrics (a, b, c) in t, and
// the same barycentrics in t's old UVs (or its vertex colours) give the colour
// the input showed at that surface point.
//
// Input : the loaded Asset (soup, VertexAttributes with the old TEXCOORD_n and
//         COLOR_0, base-colour images by material), the new corner UVs (3 per
//         triangle, glTF convention: origin top-left), RebakeOptions.
// Output: RebakeResult — a PNG texture of size x size RGBA texels, filled where
//         some triangle covers a texel centre, then dilated `padding` rings
//         outward (each empty texel next to filled ones takes their mean) so
//         bilinear filtering and mipmaps at island edges do not pull in
//         background; plus what it sampled and counts for the diagnostics.
//
// What is sampled per triangle: the base-colour image of its material through
// the image's TEXCOORD_n (bilinear, the sampler's wrap modes), times COLOR_0
// when the input has vertex colours (done in linear light, stored sRGB);
// with neither, white (the material's baseColorFactor stays in the material).
// When vertex colours were baked, `baked_colors` is set: the writer must not
// also write COLOR_0 (glTF multiplies it in: it would count twice).
//
// Images are decoded with stb_image inside the worker process (sandboxed by
// the server); dimensions are checked before decoding (<= kMaxTextureSide).
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/io/asset.h"
#include "soupuv/io/texture.h"
#include "soupuv/vec.h"

namespace soupuv::bake {

struct RebakeOptions {
  int size = 1024;    // texture side in texels
  int padding = 4;    // dilation rings, in texels
};

struct RebakeResult {
  io::Texture texture;       // PNG
  bool baked_colors = false; // COLOR_0 is in the texture (do not write it again)
  std::vector<std::string> from;  // "texture", "vertex_colors", "factor"
  size_t covered_texels = 0;
  size_t dilated_texels = 0;
  double seconds = 0;
  std::vector<std::string> warnings;
  nlohmann::json diagnostics() const;  // output.rebake in proto/diagnostics.schema.json
};

// True when the input has something to carry over: a base-colour image some
// triangle's material uses, or vertex colours. The CLI's default for --rebake.
bool has_base_color(const io::Asset& asset);

RebakeResult rebake(const io::Asset& asset, std::span<const Vec2> corner_uvs, const RebakeOptions& options = {});

// Decoded RGBA8 pixels of a PNG/JPEG (for the re-bake and its tests).
struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgba;
};
Image decode_image(std::span<const uint8_t> encoded);

}  // namespace soupuv::bake
