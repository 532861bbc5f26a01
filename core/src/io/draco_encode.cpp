// KHR_draco_mesh_compression payloads for the writer (see gltf_write_parts.h).
// Quantization 0 keeps float32 values lossless, so Draco output still round
// trips positions bit-exactly. The encoder (edgebreaker) may reorder and, at
// non-manifold vertices, duplicate points; glTF accessors must state the
// counts the decoder will produce, so we decode the payload once and read them.
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include "gltf_write_parts.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

namespace {

template <class T>
int add_attribute(draco::Mesh& mesh, draco::GeometryAttribute::Type type, draco::DataType data_type,
                  int components, const std::vector<T>& values, size_t points) {
  draco::GeometryAttribute attribute;
  attribute.Init(type, nullptr, static_cast<int8_t>(components), data_type, false, sizeof(T) * components, 0);
  int id = mesh.AddAttribute(attribute, /*identity_mapping=*/true, static_cast<uint32_t>(points));
  draco::PointAttribute* pa = mesh.attribute(id);
  for (size_t i = 0; i < points; ++i)
    pa->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)),
                          &values[i * components]);
  return id;
}

int add_float_attribute(draco::Mesh& mesh, draco::GeometryAttribute::Type type, int components,
                        const std::vector<float>& values, size_t points) {
  return add_attribute(mesh, type, draco::DT_FLOAT32, components, values, points);
}

}  // namespace

DracoPrimitive draco_encode(const OutPrimitive& primitive, int position_bits, int texcoord_bits) {
  const size_t points = primitive.vertex_count();
  const size_t faces = primitive.indices.size() / 3;
  draco::Mesh mesh;
  mesh.set_num_points(static_cast<uint32_t>(points));
  mesh.SetNumFaces(faces);
  for (size_t f = 0; f < faces; ++f) {
    draco::Mesh::Face face;
    for (int k = 0; k < 3; ++k) face[k] = draco::PointIndex(primitive.indices[f * 3 + k]);
    mesh.SetFace(draco::FaceIndex(static_cast<uint32_t>(f)), face);
  }
  int position_att = add_float_attribute(mesh, draco::GeometryAttribute::POSITION, 3,
                                         primitive.positions, points);
  int texcoord_att = add_float_attribute(mesh, draco::GeometryAttribute::TEX_COORD, 2,
                                         primitive.uvs, points);
  int normal_att = primitive.normals.empty()
                       ? -1
                       : add_float_attribute(mesh, draco::GeometryAttribute::NORMAL, 3,
                                             primitive.normals, points);
  constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedShort = 5123;
  std::vector<DracoPrimitive::Extra> extra_atts;  // id: the attribute's index until encoded
  if (!primitive.colors.empty())
    extra_atts.push_back({"COLOR_0", add_float_attribute(mesh, draco::GeometryAttribute::COLOR, 4,
                                                         primitive.colors, points), kFloat, "VEC4"});
  for (const auto& [set, values] : primitive.texcoords)
    extra_atts.push_back({"TEXCOORD_" + std::to_string(set + 1),
                          add_float_attribute(mesh, draco::GeometryAttribute::TEX_COORD, 2, values, points),
                          kFloat, "VEC2"});
  // Skinning has no Draco attribute type of its own: GENERIC, with the
  // integer type the accessor states so the decoder hands back the same values.
  for (size_t n = 0; n < primitive.skin_sets.size(); ++n) {
    const auto& set = primitive.skin_sets[n];
    int joints;
    if (joints_fit_bytes(set.joints)) {
      std::vector<uint8_t> narrow(set.joints.begin(), set.joints.end());
      joints = add_attribute(mesh, draco::GeometryAttribute::GENERIC, draco::DT_UINT8, 4, narrow, points);
    } else {
      joints = add_attribute(mesh, draco::GeometryAttribute::GENERIC, draco::DT_UINT16, 4, set.joints, points);
    }
    extra_atts.push_back({"JOINTS_" + std::to_string(n), joints,
                          joints_fit_bytes(set.joints) ? kUnsignedByte : kUnsignedShort, "VEC4"});
    extra_atts.push_back({"WEIGHTS_" + std::to_string(n),
                          add_float_attribute(mesh, draco::GeometryAttribute::GENERIC, 4, set.weights, points),
                          kFloat, "VEC4"});
  }

  draco::Encoder encoder;
  if (position_bits > 0)
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, position_bits);
  if (texcoord_bits > 0)
    encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, texcoord_bits);
  draco::EncoderBuffer buffer;
  draco::Status status = encoder.EncodeMeshToBuffer(mesh, &buffer);
  if (!status.ok())
    throw Error(ErrorCode::internal, std::string("Draco encoding failed: ") + status.error_msg());

  DracoPrimitive out;
  out.bytes.assign(buffer.data(), buffer.data() + buffer.size());
  out.position_id = static_cast<int>(mesh.attribute(position_att)->unique_id());
  out.texcoord_id = static_cast<int>(mesh.attribute(texcoord_att)->unique_id());
  if (normal_att >= 0) out.normal_id = static_cast<int>(mesh.attribute(normal_att)->unique_id());
  for (DracoPrimitive::Extra extra : extra_atts) {
    extra.id = static_cast<int>(mesh.attribute(extra.id)->unique_id());
    out.extra_ids.push_back(extra);
  }

  draco::DecoderBuffer in;
  in.Init(reinterpret_cast<const char*>(out.bytes.data()), out.bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok())
    throw Error(ErrorCode::internal,
                std::string("Draco payload does not decode: ") + decoded.status().error_msg());
  out.points = decoded.value()->num_points();
  out.faces = decoded.value()->num_faces();
  return out;
}

}  // namespace soupuv::io::detail
