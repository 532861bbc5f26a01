#include "io/accessors.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "io/checked_json.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {
namespace {

enum Component : uint64_t { kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123, kUInt = 5125, kFloat = 5126 };

uint64_t component_size(uint64_t type, const std::string& where) {
  switch (type) {
    case kByte: case kUByte: return 1;
    case kShort: case kUShort: return 2;
    case kUInt: case kFloat: return 4;
  }
  fail_input(where + ": unknown componentType " + std::to_string(type));
}

uint64_t type_components(const std::string& type, const std::string& where) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  fail_input(where + ": unknown type '" + type.substr(0, 40) + "'");
}

// One component at `p`; normalized integers map to [-1,1] / [0,1] by the glTF
// spec's formulas. Rounded to float, as a GPU would see it, so that the float
// local positions the writer keeps and the double soup positions agree exactly.
double decode_component(const uint8_t* p, uint64_t type, bool normalized) {
  double d;
  switch (type) {
    case kByte: { int8_t v; std::memcpy(&v, p, 1); d = normalized ? std::max(v / 127.0, -1.0) : v; break; }
    case kUByte: { uint8_t v = *p; d = normalized ? v / 255.0 : v; break; }
    case kShort: { int16_t v; std::memcpy(&v, p, 2); d = normalized ? std::max(v / 32767.0, -1.0) : v; break; }
    case kUShort: { uint16_t v; std::memcpy(&v, p, 2); d = normalized ? v / 65535.0 : v; break; }
    case kUInt: { uint32_t v; std::memcpy(&v, p, 4); d = v; break; }
    default: { float v; std::memcpy(&v, p, 4); return v; }
  }
  return double(float(d));
}

uint32_t decode_index(const uint8_t* p, uint64_t type) {
  switch (type) {
    case kUByte: return *p;
    case kUShort: { uint16_t v; std::memcpy(&v, p, 2); return v; }
    default: { uint32_t v; std::memcpy(&v, p, 4); return v; }
  }
}

// Byte range of `count` elements of `element_size` bytes every `stride` bytes
// starting `offset` bytes into the view: checked, overflow-safe.
std::span<const uint8_t> element_range(const ViewBytes& view, uint64_t offset, uint64_t count,
                                       uint64_t element_size, uint64_t stride, const std::string& where) {
  if (count == 0) return {};
  uint64_t end = checked_add(checked_add(offset, checked_mul(stride, count - 1, where), where), element_size, where);
  if (end > view.bytes.size())
    fail_input(where + ": byteOffset " + std::to_string(offset) + " + stride " + std::to_string(stride) +
               " * (count " + std::to_string(count) + " - 1) + element " + std::to_string(element_size) +
               " = " + std::to_string(end) + " bytes exceeds its bufferView of " +
               std::to_string(view.bytes.size()) + " bytes");
  return view.bytes.subspan(size_t(offset), size_t(end - offset));
}

// The parsed, checked description of one accessor and a reader for it.
struct Accessor {
  std::string name;
  uint64_t count = 0;
  uint64_t component_type = 0;
  uint64_t components = 0;
  bool normalized = false;
  uint64_t element_size = 0;
  uint64_t stride = 0;
  std::span<const uint8_t> data;  // empty: no bufferView (all zeros)
  const nlohmann::json* sparse = nullptr;
};

Accessor describe(const nlohmann::json& doc, BufferTable& buffers, uint64_t index, uint64_t max_bytes) {
  Accessor a;
  a.name = "accessor " + std::to_string(index);
  const nlohmann::json& acc = element(doc, "accessors", index, "primitive");
  a.count = get_uint(acc, "count", a.name);
  a.component_type = get_uint(acc, "componentType", a.name);
  uint64_t csize = component_size(a.component_type, a.name);
  auto type = get_opt_string(acc, "type", a.name);
  if (!type) fail_input(a.name + " has no type");
  a.components = type_components(*type, a.name);
  a.normalized = get_opt_bool(acc, "normalized", false, a.name);
  a.element_size = csize * a.components;
  // Whatever the buffers hold, we materialize count elements: cap that first.
  if (checked_mul(a.count, a.element_size, a.name) > max_bytes)
    throw Error(ErrorCode::limit_exceeded, a.name + ": count " + std::to_string(a.count) + " exceeds the byte limit");
  a.sparse = find_member(acc, "sparse", a.name);
  auto view_index = get_opt_uint(acc, "bufferView", a.name);
  if (view_index) {
    ViewBytes view = buffers.view(*view_index, a.name);
    a.stride = view.stride ? view.stride : a.element_size;
    if (a.stride < a.element_size)
      fail_input(a.name + ": byteStride " + std::to_string(a.stride) + " is smaller than the element size " +
                 std::to_string(a.element_size));
    uint64_t offset = get_opt_uint(acc, "byteOffset", a.name).value_or(0);
    if (offset % csize != 0) fail_input(a.name + ": byteOffset is not a multiple of the component size");
    a.data = element_range(view, offset, a.count, a.element_size, a.stride, a.name);
  }
  return a;
}

// Applies accessor.sparse: `write(i, bytes)` replaces element i with `bytes`.
template <typename Write>
void apply_sparse(const Accessor& a, BufferTable& buffers, Write write) {
  if (!a.sparse) return;
  std::string where = a.name + ".sparse";
  uint64_t n = get_uint(*a.sparse, "count", where);
  if (n > a.count) fail_input(where + ": count " + std::to_string(n) + " exceeds the accessor count");
  if (n == 0) return;
  const nlohmann::json* idx = find_member(*a.sparse, "indices", where);
  const nlohmann::json* val = find_member(*a.sparse, "values", where);
  if (!idx || !val) fail_input(where + " lacks indices or values");
  uint64_t idx_type = get_uint(*idx, "componentType", where + ".indices");
  if (idx_type != kUByte && idx_type != kUShort && idx_type != kUInt)
    fail_input(where + ".indices: componentType " + std::to_string(idx_type) + " is not an unsigned integer");
  uint64_t isize = component_size(idx_type, where);
  ViewBytes iview = buffers.view(get_uint(*idx, "bufferView", where + ".indices"), where + ".indices");
  ViewBytes vview = buffers.view(get_uint(*val, "bufferView", where + ".values"), where + ".values");
  // Sparse data is tightly packed: the views' byteStride does not apply.
  auto ibytes = element_range(iview, get_opt_uint(*idx, "byteOffset", where).value_or(0), n, isize, isize,
                              where + ".indices");
  auto vbytes = element_range(vview, get_opt_uint(*val, "byteOffset", where).value_or(0), n, a.element_size,
                              a.element_size, where + ".values");
  for (uint64_t k = 0; k < n; ++k) {
    uint32_t i = decode_index(ibytes.data() + k * isize, idx_type);
    if (i >= a.count)
      fail_input(where + ": index " + std::to_string(i) + " >= accessor count " + std::to_string(a.count));
    write(i, vbytes.data() + k * a.element_size);
  }
}

}  // namespace

uint64_t accessor_count(const nlohmann::json& doc, uint64_t accessor) {
  const nlohmann::json& acc = element(doc, "accessors", accessor, "primitive");
  return get_uint(acc, "count", "accessor " + std::to_string(accessor));
}

std::vector<Vec3> read_positions(const nlohmann::json& doc, BufferTable& buffers, uint64_t accessor,
                                 uint64_t max_bytes) {
  Accessor a = describe(doc, buffers, accessor, max_bytes);
  if (a.components != 3) fail_input(a.name + ": POSITION must be VEC3");
  uint64_t csize = a.element_size / 3;
  auto decode = [&](const uint8_t* p) {
    return Vec3{decode_component(p, a.component_type, a.normalized),
                decode_component(p + csize, a.component_type, a.normalized),
                decode_component(p + 2 * csize, a.component_type, a.normalized)};
  };
  std::vector<Vec3> out(size_t(a.count));
  if (!a.data.empty())
    for (uint64_t i = 0; i < a.count; ++i) out[i] = decode(a.data.data() + i * a.stride);
  apply_sparse(a, buffers, [&](uint32_t i, const uint8_t* p) { out[i] = decode(p); });
  return out;
}

std::vector<float> read_floats(const nlohmann::json& doc, BufferTable& buffers, uint64_t accessor,
                               uint64_t max_bytes, uint64_t& components) {
  Accessor a = describe(doc, buffers, accessor, max_bytes);
  components = a.components;
  const uint64_t csize = a.element_size / a.components;
  std::vector<float> out(size_t(a.count * a.components), 0.0f);
  auto decode = [&](uint64_t i, const uint8_t* p) {
    for (uint64_t c = 0; c < a.components; ++c)
      out[size_t(i * a.components + c)] = float(decode_component(p + c * csize, a.component_type, a.normalized));
  };
  if (!a.data.empty())
    for (uint64_t i = 0; i < a.count; ++i) decode(i, a.data.data() + i * a.stride);
  apply_sparse(a, buffers, [&](uint32_t i, const uint8_t* p) { decode(i, p); });
  return out;
}

std::vector<uint32_t> read_indices(const nlohmann::json& doc, BufferTable& buffers, uint64_t accessor,
                                   uint64_t max_bytes) {
  Accessor a = describe(doc, buffers, accessor, max_bytes);
  if (a.components != 1) fail_input(a.name + ": indices must be SCALAR");
  if (a.component_type != kUByte && a.component_type != kUShort && a.component_type != kUInt)
    fail_input(a.name + ": indices componentType " + std::to_string(a.component_type) +
               " is not UNSIGNED_BYTE/SHORT/INT");
  std::vector<uint32_t> out(size_t(a.count), 0);
  if (!a.data.empty())
    for (uint64_t i = 0; i < a.count; ++i) out[i] = decode_index(a.data.data() + i * a.stride, a.component_type);
  apply_sparse(a, buffers, [&](uint32_t i, const uint8_t* p) { out[i] = decode_index(p, a.component_type); });
  return out;
}

}  // namespace soupuv::io::detail
