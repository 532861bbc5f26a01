// Writing the mapped soup back as a textured GLB, in the structure it came in.
//
// Input : the loaded Asset (soup + source document + local positions) and
//         corner UVs, 3 per soup triangle (UV origin at the image's top-left,
//         as glTF defines it); WriteOptions.
// Output: the GLB bytes and what was dropped or changed (warnings), or
//         soupuv::Error{invalid_input} when the UVs do not match the soup, or
//         Error{internal} when the Draco encoder fails.
//
// What the GLB keeps and changes:
//  - every soup triangle is written with its positions bit-exact in its own
//    frame (Asset::local_positions), under its original node (name, matrix or
//    TRS, children, scenes kept); one output mesh per (node, mesh) instance,
//    because each instance of a mesh gets its own UVs; one output primitive per
//    source primitive that still has triangles, with its material;
//  - vertices are welded where local position, UV and every kept attribute
//    agree, so they are split exactly where UVs differ; TEXCOORD_0 (the new
//    map) is float32;
//  - vertex attributes kept from the source (Asset::attributes): NORMAL
//    (normalized; flat when options.normals), COLOR_0 (as float RGBA, unless
//    !keep_colors), every TEXCOORD_n moved to TEXCOORD_n+1, and JOINTS_n /
//    WEIGHTS_n with their values as read (joints UNSIGNED_BYTE when they fit,
//    else UNSIGNED_SHORT; weights float), except that a vertex whose weights
//    do not sum to 1 gets them normalized (glTF requires it, the validator
//    refuses it, renderers normalize on loading; counted in a warning); the
//    loader warns about the ones it dropped (TANGENT, others);
//  - skins are kept (Asset::skins holds their inverse bind matrices): joints
//    and skeleton re-numbered to the output nodes, and the skin on the node of
//    each output mesh made from a skinned node. A skin whose joint or skeleton
//    is not exactly one output node (a node with several parents is copied per
//    path; a node in no scene is left out) is dropped with its meshes'
//    JOINTS_n/WEIGHTS_n and a warning naming the node;
//  - materials keep name, factors, alphaMode, alphaCutoff, doubleSided,
//    emissiveFactor; baseColorTexture becomes our texture on TEXCOORD_0; other
//    textures (they referred to the old UVs) and material extensions are dropped
//    with a warning; NORMAL only when asked (flat, per triangle);
//  - animations and morph targets are dropped with a warning: the output is
//    the static bind pose;
//  - the texture image lives in the BIN chunk (bufferView + mimeType);
//  - with options.draco each primitive is KHR_draco_mesh_compression-encoded
//    (required extension); its accessors keep counts and POSITION min/max.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "soupuv/io/asset.h"
#include "soupuv/io/texture.h"
#include "soupuv/vec.h"

namespace soupuv::io {

struct WriteOptions {
  // nullopt: a generated UV-check texture of check_texture_size pixels.
  std::optional<Texture> texture;
  int check_texture_size = 1024;
  bool draco = false;
  // Flat NORMALs (each triangle's unit normal in its own frame): faceted
  // shading, which is what a soup is; splits vertices between facets.
  bool normals = false;
  // Draco quantization bits; 0 keeps the float32 values lossless (bit-exact).
  int draco_position_bits = 0;
  int draco_texcoord_bits = 0;
  // COLOR_0 from the source; off when the colours were baked into the texture
  // (glTF multiplies COLOR_0 into the base colour: it would count twice).
  bool keep_colors = true;
  std::string texture_name;  // the image's name ("" : by its kind)
  std::string generator = "soupuv";
};

struct WriteResult {
  std::vector<uint8_t> glb;
  std::vector<std::string> warnings;
  size_t meshes = 0;      // output meshes, one per (node, mesh) instance
  size_t primitives = 0;
  size_t vertices = 0;    // after welding equal (position, UV) corners
  size_t triangles = 0;
  size_t nonfinite_uvs = 0;  // corners whose UV was NaN/inf, written as (0,0)
  size_t degenerate_normals = 0;  // with normals: triangles degenerate in float (+z written)
  std::vector<std::string> attributes;  // vertex attributes written (glTF names)
  double seconds = 0;
};

WriteResult write_glb(const Asset& asset, std::span<const Vec2> corner_uvs,
                      const WriteOptions& options = {});

}  // namespace soupuv::io
