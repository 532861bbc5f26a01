#include "io/draco_decode.h"

#include <cmath>
#include <cstring>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include "io/checked_json.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

bool has_draco_magic(std::span<const uint8_t> bytes) {
  return bytes.size() >= 5 && std::memcmp(bytes.data(), "DRACO", 5) == 0;
}

DracoMesh decode_draco(std::span<const uint8_t> bytes, int64_t position_attribute_id,
                       uint64_t max_triangles, const std::string& where) {
  if (!has_draco_magic(bytes)) fail_input(where + ": Draco payload does not start with 'DRACO'");
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) fail_input(where + ": Draco header unreadable: " + type.status().error_msg_string());
  if (type.value() == draco::POINT_CLOUD)
    throw Error(ErrorCode::no_triangles, where + ": Draco point cloud has no triangles to map");
  if (type.value() != draco::TRIANGULAR_MESH) fail_input(where + ": Draco payload is not a triangle mesh");

  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) fail_input(where + ": Draco decoding failed: " + decoded.status().error_msg_string());
  const draco::Mesh& mesh = *decoded.value();

  if (mesh.num_faces() > max_triangles)
    throw Error(ErrorCode::limit_exceeded, where + ": Draco mesh has " + std::to_string(mesh.num_faces()) +
                                               " faces, over the triangle limit");
  const draco::PointAttribute* pos =
      position_attribute_id >= 0
          ? mesh.GetAttributeByUniqueId(uint32_t(position_attribute_id))
          : mesh.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (!pos) fail_input(where + ": Draco mesh has no POSITION attribute" +
                       (position_attribute_id >= 0 ? " with id " + std::to_string(position_attribute_id) : ""));
  if (pos->num_components() < 3) fail_input(where + ": Draco POSITION has fewer than 3 components");

  // Draco points map to attribute values through an optional index map;
  // check both levels before reading anything.
  const uint32_t points = mesh.num_points();
  if (!pos->is_mapping_identity() && pos->indices_map_size() < points)
    fail_input(where + ": Draco POSITION map shorter than the point count");
  DracoMesh out;
  out.positions.resize(points);
  for (uint32_t p = 0; p < points; ++p) {
    draco::AttributeValueIndex v = pos->mapped_index(draco::PointIndex(p));
    if (v.value() >= pos->size()) fail_input(where + ": Draco POSITION value index out of range");
    float xyz[3];
    if (!pos->ConvertValue<float>(v, 3, xyz)) fail_input(where + ": Draco POSITION values unreadable");
    out.positions[p] = {xyz[0], xyz[1], xyz[2]};
  }
  out.triangles.resize(mesh.num_faces());
  for (uint32_t f = 0; f < mesh.num_faces(); ++f) {
    const auto& face = mesh.face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      uint32_t i = face[k].value();
      if (i >= points)
        fail_input(where + ": Draco face " + std::to_string(f) + " index " + std::to_string(i) +
                   " >= point count " + std::to_string(points));
      out.triangles[f][k] = i;
    }
  }
  return out;
}

}  // namespace soupuv::io::detail
