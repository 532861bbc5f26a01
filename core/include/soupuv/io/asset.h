// What the loader returns: the soup plus what the writer needs to put every
// triangle back in its original node/mesh/primitive/material structure.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/soup.h"

namespace soupuv::io {

enum class Format { glb, gltf, drc };

// 4x4 matrix, column-major like glTF's node.matrix.
using Mat4 = std::array<double, 16>;

// One mesh placed in the world by one path through the node graph. Usually one
// per mesh-carrying node; a node reachable along several parent paths (as in
// CubeScaledInstances, where one child has four parents) gets one per path.
struct MeshInstance {
  int32_t node = -1;   // the node carrying the mesh (-1 for a raw .drc)
  int32_t mesh = 0;
  Mat4 world{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // local -> world
};

// Vertex attributes other than POSITION, one entry per soup vertex (parallel
// to Soup::positions), as the source stored them in the primitive's own frame.
// An array is empty when no primitive had the attribute; `present` says, per
// soup vertex, which ones its primitive had (bits below), since primitives may
// differ. Read from plain accessors only (Draco payloads: POSITION only).
struct VertexAttributes {
  static constexpr uint32_t kNormal = 1u, kColor = 2u;
  static constexpr uint32_t texcoord_bit(int n) { return 4u << n; }
  static constexpr int kMaxTexcoords = 8;
  // JOINTS_n and WEIGHTS_n travel as a pair (one is meaningless without the
  // other), so one bit says both are present.
  static constexpr uint32_t skin_bit(int n) { return 1u << (16 + n); }
  static constexpr int kMaxSkinSets = 4;
  std::vector<uint32_t> present;                       // bit mask per soup vertex
  std::vector<std::array<float, 3>> normals;           // NORMAL
  std::vector<std::array<float, 4>> colors;            // COLOR_0 as RGBA (alpha 1 when VEC3)
  std::vector<std::vector<std::array<float, 2>>> texcoords;  // [n][vertex]: TEXCOORD_n
  std::vector<std::vector<std::array<uint16_t, 4>>> joints;  // [n][vertex]: JOINTS_n (skin joint indices)
  std::vector<std::vector<std::array<float, 4>>> weights;    // [n][vertex]: WEIGHTS_n, as decoded
  bool empty() const { return normals.empty() && colors.empty() && texcoords.empty() && joints.empty(); }
};

// What the writer needs of a source skin besides its JSON (joints, skeleton,
// name stay in Asset::document): the inverse bind matrices, which live in a
// buffer the writer no longer has.
struct SourceSkin {
  bool readable = true;  // false: its inverseBindMatrices could not be read (warned)
  // 16 floats per joint, column-major as stored; empty when the source has
  // none (glTF then means identity matrices, and so does the output).
  std::vector<float> inverse_bind_matrices;
};

// A material's base-colour texture image as the source holds it (encoded
// PNG/JPEG bytes), for re-baking onto the new map.
struct SourceImage {
  std::vector<uint8_t> bytes;
  std::string mime_type;
  int tex_coord = 0;            // which TEXCOORD_n it is sampled through
  int wrap_s = 10497, wrap_t = 10497;  // sampler wrap modes (REPEAT default)
};

struct Asset {
  Format format = Format::glb;
  Soup soup;  // world space; soup.origins[t] says where triangle t came from
  // The source glTF JSON as parsed (nodes, meshes, materials, ...). Buffers
  // that were data: URIs have their "uri" removed (the payload is not kept);
  // everything else, image URIs included, is as in the source. For a raw .drc
  // a minimal synthesized document (one mesh, one primitive, no nodes).
  nlohmann::json document;
  size_t dropped_degenerate = 0;  // zero-area triangles removed while loading
  size_t skipped_primitives = 0;  // points/lines primitives skipped (with a warning)
  // For the writer's bit-exact round trip (requested by io-write): the float32
  // value of soup vertex v in its primitive's own frame, exactly as read from
  // the accessor (dequantized, before any node transform); parallel to
  // soup.positions. The writer needs each soup vertex to be used by triangles
  // of one (node, mesh) instance only (instanced meshes: one copy per node).
  // Empty when the loader did not record them: the writer then derives local
  // positions from world ones (not bit-exact under non-identity transforms).
  std::vector<std::array<float, 3>> local_positions;

  // Which instance each soup triangle belongs to (index into `instances`),
  // parallel to soup.triangles; the loader fills both. Vertices are never
  // shared between instances or primitives; within one primitive instance only
  // vertices that kept triangles use are present. Corner order is the source's
  // (not flipped for mirroring matrices). Normalized-integer positions are
  // dequantized to float first, so local_positions and soup.positions agree
  // exactly under identity transforms.
  std::vector<uint32_t> triangle_instance;
  std::vector<MeshInstance> instances;

  VertexAttributes attributes;
  std::vector<SourceSkin> skins;  // parallel to document["skins"]
  // Base-colour images by material index (materials whose image could be read).
  std::map<int32_t, SourceImage> base_color_images;
};

}  // namespace soupuv::io
