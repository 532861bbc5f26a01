// soupuv-render IN.glb -o OUT.png [--view N]: renders a textured GLB (as
// `soupuv map` writes it: float32 POSITION and TEXCOORD_0, TRIANGLES, a
// baseColorTexture in the file) from four directions into one PNG, so a
// person can look at texture continuity. Without a texture in the file the
// UV-check texture is used. Draco-compressed files are not read (Debian's
// tinygltf has no Draco); map without --draco to preview.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include <array>
#include <fstream>
#include <iostream>

#include "render.h"
#include "soupuv/io/texture.h"
#include "soupuv/quality/uv_layout.h"

using namespace soupuv;

namespace {

using Mat4 = std::array<double, 16>;  // column-major, as glTF

Mat4 identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 mul(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int rr = 0; rr < 4; ++rr)
      for (int k = 0; k < 4; ++k) r[c * 4 + rr] += a[k * 4 + rr] * b[c * 4 + k];
  return r;
}

Mat4 local_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) {
    Mat4 m;
    for (int i = 0; i < 16; ++i) m[i] = n.matrix[i];
    return m;
  }
  Mat4 t = identity(), r = identity(), s = identity();
  if (n.translation.size() == 3) { t[12] = n.translation[0]; t[13] = n.translation[1]; t[14] = n.translation[2]; }
  if (n.rotation.size() == 4) {
    double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
    r = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0,
         2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0,
         2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0, 0, 0, 0, 1};
  }
  if (n.scale.size() == 3) { s[0] = n.scale[0]; s[5] = n.scale[1]; s[10] = n.scale[2]; }
  return mul(t, mul(r, s));
}

// Element i of a float accessor with `comps` components.
bool read_floats(const tinygltf::Model& m, int accessor, size_t i, int comps, double* out) {
  const auto& a = m.accessors[accessor];
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.bufferView < 0 || i >= a.count) return false;
  const auto& v = m.bufferViews[a.bufferView];
  size_t stride = v.byteStride ? v.byteStride : size_t(comps) * 4;
  size_t at = v.byteOffset + a.byteOffset + i * stride;
  const auto& buf = m.buffers[v.buffer].data;
  if (at + size_t(comps) * 4 > buf.size()) return false;
  for (int c = 0; c < comps; ++c) {
    float f;
    std::memcpy(&f, buf.data() + at + 4 * c, 4);
    out[c] = f;
  }
  return true;
}

bool read_index(const tinygltf::Model& m, int accessor, size_t i, uint32_t& out) {
  const auto& a = m.accessors[accessor];
  if (a.bufferView < 0 || i >= a.count) return false;
  const auto& v = m.bufferViews[a.bufferView];
  int size = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ? 1
             : a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2 : 4;
  size_t stride = v.byteStride ? v.byteStride : size_t(size);
  size_t at = v.byteOffset + a.byteOffset + i * stride;
  const auto& buf = m.buffers[v.buffer].data;
  if (at + size > buf.size()) return false;
  out = 0;
  std::memcpy(&out, buf.data() + at, size);  // little-endian host
  return true;
}

void collect(const tinygltf::Model& m, int node, const Mat4& parent, std::vector<Vec3>& corners,
             std::vector<Vec2>& uvs, int& material, int depth) {
  if (node < 0 || node >= int(m.nodes.size()) || depth > 64) return;
  const auto& n = m.nodes[node];
  Mat4 world = mul(parent, local_matrix(n));
  if (n.mesh >= 0 && n.mesh < int(m.meshes.size())) {
    for (const auto& p : m.meshes[n.mesh].primitives) {
      if (p.mode != TINYGLTF_MODE_TRIANGLES) continue;
      auto pos = p.attributes.find("POSITION"), tex = p.attributes.find("TEXCOORD_0");
      if (pos == p.attributes.end()) continue;
      size_t count = p.indices >= 0 ? m.accessors[p.indices].count : m.accessors[pos->second].count;
      if (material < 0) material = p.material;
      for (size_t i = 0; i + 2 < count; i += 3)
        for (int k = 0; k < 3; ++k) {
          uint32_t idx = uint32_t(i + k);
          if (p.indices >= 0 && !read_index(m, p.indices, i + k, idx)) return;
          double xyz[3] = {0, 0, 0}, st[2] = {NAN, NAN};
          if (!read_floats(m, pos->second, idx, 3, xyz)) return;
          if (tex != p.attributes.end()) read_floats(m, tex->second, idx, 2, st);
          Vec3 w{world[0] * xyz[0] + world[4] * xyz[1] + world[8] * xyz[2] + world[12],
                 world[1] * xyz[0] + world[5] * xyz[1] + world[9] * xyz[2] + world[13],
                 world[2] * xyz[0] + world[6] * xyz[1] + world[10] * xyz[2] + world[14]};
          corners.push_back(w);
          uvs.push_back({st[0], st[1]});
        }
    }
  }
  for (int c : n.children) collect(m, c, world, corners, uvs, material, depth + 1);
}

}  // namespace

int main(int argc, char** argv) {
  std::string in, out;
  int view = 512;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "-o" && i + 1 < argc) out = argv[++i];
    else if (a == "--view" && i + 1 < argc) view = std::stoi(argv[++i]);
    else in = a;
  }
  if (in.empty() || out.empty() || view < 16 || view > 4096) {
    std::cerr << "usage: soupuv-render IN.glb -o OUT.png [--view PIXELS]\n";
    return 2;
  }
  try {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    if (!loader.LoadBinaryFromFile(&model, &err, &warn, in)) {
      std::cerr << "soupuv-render: " << in << ": " << err << "\n";
      return 1;
    }
    std::vector<Vec3> corners;
    std::vector<Vec2> uvs;
    int material = -1;
    int scene = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (scene < int(model.scenes.size()))
      for (int n : model.scenes[scene].nodes) collect(model, n, identity(), corners, uvs, material, 0);
    if (corners.empty()) {
      std::cerr << "soupuv-render: no triangles in " << in << "\n";
      return 1;
    }
    render::Rgba texture;
    if (material >= 0) {
      int t = model.materials[material].pbrMetallicRoughness.baseColorTexture.index;
      if (t >= 0 && model.textures[t].source >= 0) {
        const auto& img = model.images[model.textures[t].source];
        if (img.width > 0 && img.component >= 3 && !img.image.empty()) {
          texture.width = img.width;
          texture.height = img.height;
          texture.pixels.resize(size_t(img.width) * img.height * 4);
          for (size_t p = 0; p < size_t(img.width) * img.height; ++p)
            for (int c = 0; c < 4; ++c)
              texture.pixels[4 * p + c] = c < img.component ? img.image[img.component * p + c] : 255;
        }
      }
    }
    if (texture.pixels.empty()) texture = render::decode_image(io::uv_check_texture(1024).bytes);
    render::Rgba image = render::render_views(corners, uvs, texture, view);
    auto png = quality::encode_png(image.pixels, image.width, image.height);
    std::ofstream(out, std::ios::binary).write(reinterpret_cast<const char*>(png.data()), long(png.size()));
    std::cerr << "soupuv-render: " << corners.size() / 3 << " triangles -> " << out << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "soupuv-render: " << e.what() << "\n";
    return 1;
  }
}
