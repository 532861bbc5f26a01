#include "pipeline/field_codec.h"

#include "soupuv/cache/bytes.h"

namespace soupuv::pipeline {

namespace {
void put_strings(cache::ByteWriter& w, const std::vector<std::string>& v) {
  w.put<uint64_t>(v.size());
  for (const auto& s : v) w.put_string(s);
}
std::vector<std::string> get_strings(cache::ByteReader& r) {
  uint64_t n = r.get<uint64_t>();
  std::vector<std::string> v;
  for (uint64_t i = 0; i < n; ++i) v.push_back(r.get_string());
  return v;
}
}  // namespace

cache::Bytes encode(const field::ChargeResult& c) {
  cache::ByteWriter w;
  w.put_vector(c.positions);
  w.put_vector(c.triangles);
  w.put_vector(c.parent);
  w.put_vector(c.charges);
  w.put(c.quadrature_degree);
  w.put(c.fmm_order);
  w.put(c.fmm_theta);
  w.put_string(c.solver);
  w.put(c.iterations);
  w.put(c.seconds);
  w.put(c.solve_seconds);
  w.put(c.converged);
  w.put(c.max_rel_potential_error);
  w.put_string(c.verified_by);
  w.put(c.mean_potential);
  w.put_vector(c.history);
  w.put_vector(c.history_seconds);
  w.put_vector(c.history_iterations);
  w.put<uint64_t>(c.source_triangles);
  w.put<uint64_t>(c.refined_triangles);
  put_strings(w, c.warnings);
  return w.take();
}

field::ChargeResult decode_charges(std::span<const uint8_t> bytes) {
  cache::ByteReader r(bytes);
  field::ChargeResult c;
  c.positions = r.get_vector<Vec3>();
  c.triangles = r.get_vector<Tri>();
  c.parent = r.get_vector<uint32_t>();
  c.charges = r.get_vector<double>();
  c.quadrature_degree = r.get<int>();
  c.fmm_order = r.get<int>();
  c.fmm_theta = r.get<double>();
  c.solver = r.get_string();
  c.iterations = r.get<int>();
  c.seconds = r.get<double>();
  c.solve_seconds = r.get<double>();
  c.converged = r.get<bool>();
  c.max_rel_potential_error = r.get<double>();
  c.verified_by = r.get_string();
  c.mean_potential = r.get<double>();
  c.history = r.get_vector<double>();
  c.history_seconds = r.get_vector<double>();
  c.history_iterations = r.get_vector<int>();
  c.source_triangles = r.get<uint64_t>();
  c.refined_triangles = r.get<uint64_t>();
  c.warnings = get_strings(r);
  if (!r.done()) throw Error(ErrorCode::internal, "cached charges have trailing bytes");
  return c;
}

cache::Bytes encode(const field::FieldLines& l) {
  cache::ByteWriter w;
  w.put_vector(l.points);
  w.put_vector(l.offsets);
  w.put_vector(l.ends);
  w.put_vector(l.corner);
  return w.take();
}

field::FieldLines decode_lines(std::span<const uint8_t> bytes) {
  cache::ByteReader r(bytes);
  field::FieldLines l;
  l.points = r.get_vector<Vec3>();
  l.offsets = r.get_vector<uint32_t>();
  l.ends = r.get_vector<field::LineEnd>();
  l.corner = r.get_vector<uint32_t>();
  if (!r.done() || l.offsets.size() != l.ends.size() + 1 || l.corner.size() != l.ends.size() ||
      l.offsets.back() != l.points.size())
    throw Error(ErrorCode::internal, "cached field lines are inconsistent");
  return l;
}

}  // namespace soupuv::pipeline
