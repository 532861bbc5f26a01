#include "pipeline/field_branch.h"

#include <chrono>
#include <memory>

#include "pipeline/field_codec.h"
#include "pipeline/shared_seeds.h"
#include "soupuv/cache/bytes.h"
#include "soupuv/geometry/surface_hit_bvh.h"
#include "soupuv/hash.h"
#include "soupuv/proxy/offset_policy.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/field/intersect.h"
#include "soupuv/field/orient.h"

namespace soupuv::pipeline {

namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A mesh's content, for the lines' key when they stop at it.
std::string mesh_hash(const TriMesh& mesh) {
  Hasher h;
  h.add_array(mesh.vertices);
  h.add_array(mesh.faces);
  return h.hex();
}

// A cache-key part from raw bytes (hashed as they are, never formatted).
std::string key_part(cache::ByteWriter&& w) {
  const std::vector<uint8_t> bytes = w.take();
  return std::string(bytes.begin(), bytes.end());
}

// Every option that changes the result (threads do not), for cache keys:
// each field's bytes in a fixed order (fields one by one, so no struct
// padding enters the key).
std::string charge_params(const field::ChargeOptions& o) {
  cache::ByteWriter w;
  w.put(int(o.solver)), w.put(o.tolerance), w.put(o.quadrature_degree), w.put(o.fmm_order), w.put(o.fmm_theta);
  w.put(o.refine_area_ratio);
  // The effective Krylov budget, so a change of its default is a new key.
  w.put(o.solver == field::ChargeOptions::Solver::krylov && o.max_iterations == 0 ? field::kKrylovIterationBudget
                                                                                 : o.max_iterations);
  w.put(o.max_seconds), w.put(o.direct_initialization);
  return key_part(std::move(w));
}

// `o`: the trace options as traced (stop sphere and box filled in).
std::string trace_params(const FieldBranchOptions& b, const field::TraceOptions& o) {
  cache::ByteWriter w;
  w.put(int(o.integrator)), w.put(o.max_steps), w.put(o.step), w.put(o.start_offset), w.put(o.start_offset_fraction);
  w.put(o.stop_radius);
  for (const Vec3& c : {o.stop_box.lo, o.stop_box.hi}) w.put(c.x), w.put(c.y), w.put(c.z);
  w.put(o.fmm_order), w.put(o.fmm_theta), w.put(o.keep_points), w.put(o.adaptive_step), w.put(o.near_step_fraction);
  w.put(o.max_turn_per_step), w.put(o.max_step_growth), w.put(o.direct), w.put(o.fmm_leaf_size);
  w.put(o.trapped_steps), w.put(b.orient_sides), w.put(b.share_lines);
  w.put(b.weld_tolerance), w.put(b.weld_edge_fraction), w.put(b.seed_edge_weld_tolerance), w.put(b.seed_edge_fraction);
  w.put_string(geometry::kEdgeWeldAlgorithm);
  return key_part(std::move(w));
}

nlohmann::json charge_json(const field::ChargeResult& c) {
  return {{"solver", c.solver},
          {"iterations", c.iterations},
          {"converged", c.converged},
          {"max_rel_potential_error", c.max_rel_potential_error},
          {"verified_by", c.verified_by},
          {"source_triangles", c.source_triangles},
          {"refined_triangles", c.refined_triangles},
          {"solve_seconds", c.solve_seconds},
          {"history", c.history},
          {"history_seconds", c.history_seconds},
          {"history_iterations", c.history_iterations},
          {"warnings", c.warnings}};
}

void add_stats(nlohmann::json& j, const field::TraceStats& s) {
  auto add = [&](const char* k, double v) { j[k] = j.value(k, 0.0) + v; };
  add("seconds", s.seconds);
  add("build_seconds", s.build_seconds);
  add("evaluations", double(s.evaluations));
  add("steps", double(s.steps));
  add("escaped", double(s.escaped));
  add("step_limit", double(s.step_limit));
  add("stalled", double(s.stalled));
  add("trapped", double(s.trapped));
  add("reached", double(s.reached));
  add("grown_steps", double(s.grown_steps));
  add("grown_steps_redone", double(s.grown_steps_redone));
  add("expansions", double(s.expansions));
  add("m2l_operations", double(s.m2l_operations));
  add("m2l_terms", double(s.m2l_terms));
}

// Lines for the corners in `seeds` replace those of `base` (same corner).
field::FieldLines merge_lines(const field::FieldLines& base, const field::FieldLines& fresh) {
  std::vector<int64_t> replacement(base.size(), -1);
  std::vector<int64_t> line_of_corner;
  for (size_t i = 0; i < base.size(); ++i) {
    if (base.corner[i] >= line_of_corner.size()) line_of_corner.resize(base.corner[i] + 1, -1);
    line_of_corner[base.corner[i]] = int64_t(i);
  }
  for (size_t j = 0; j < fresh.size(); ++j)
    if (fresh.corner[j] < line_of_corner.size() && line_of_corner[fresh.corner[j]] >= 0)
      replacement[line_of_corner[fresh.corner[j]]] = int64_t(j);
  field::FieldLines out;
  for (size_t i = 0; i < base.size(); ++i) {
    const field::FieldLines& src = replacement[i] >= 0 ? fresh : base;
    size_t k = replacement[i] >= 0 ? size_t(replacement[i]) : i;
    out.points.insert(out.points.end(), src.points.begin() + src.offsets[k],
                      src.points.begin() + src.offsets[k + 1]);
    out.offsets.push_back(uint32_t(out.points.size()));
    out.ends.push_back(src.ends[k]);
    out.corner.push_back(src.corner[k]);
  }
  return out;
}

// Traces `again` (seeds whose side changed) with the tracer that traced
// `lines` (its FMM serves both) and puts their lines in place of the old ones.
void retrace(field::FieldLineTracer& tracer, const std::vector<field::TraceSeed>& again, Progress& progress,
             field::FieldLines& lines) {
  if (again.empty()) return;
  lines = merge_lines(lines, tracer.trace(again, progress));
}


// One line per (welded position, component). Every seed's side is probed
// (the |E| rule), each component takes the side of an area-weighted vote of
// its seeds (§12.4), and every line is then traced once, on its component's
// side.
// Why probe first: a line's side is its probed side, so the vote is known
// before any line is traced. Tracing first and then tracing again the lines
// that left on the outvoted side traced those twice, a third of the lines
// and more on noisy soups (docs/tuning.md, session 28).
void trace_shared(const Soup& soup, const field::ChargeResult& charges,
                  const field::TraceOptions& trace_options, const FieldBranchOptions& options,
                  Progress& progress, FieldBranchResult& r) {
  const auto t_weld = std::chrono::steady_clock::now();
  if (options.seed_edge_weld_tolerance > 0)
    r.seed_edge_weld = geometry::weld_by_edges(soup, options.seed_edge_weld_tolerance, 1.0, false);
  const geometry::Weld weld =
      r.seed_edge_weld
          ? geometry::extend_weld(soup, *r.seed_edge_weld, options.weld_tolerance,
                                 options.seed_edge_fraction > 0 ? options.seed_edge_fraction
                                                                : options.weld_edge_fraction)
          : geometry::weld_corners(soup, options.weld_tolerance, options.weld_edge_fraction);
  r.seconds_seed_weld = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_weld).count();
  const auto adjacency = geometry::edge_adjacency(weld, soup.triangles.size());
  const field::Orientation orientation = field::consistent_orientation(soup, adjacency);
  SharedSeeds shared = shared_seeds(soup, weld, orientation);

  field::FieldLineTracer tracer(charges, trace_options);
  progress.update("trace", 0.05);
  const std::vector<int> probed = tracer.probe_sides(shared.seeds);
  const size_t groups = shared.seeds.size();
  std::vector<int8_t> side(groups);
  std::vector<double> vote(orientation.components, 0.0);
  for (size_t g = 0; g < groups; ++g) {
    side[g] = int8_t(probed_line_side(shared.seeds[g], probed[g]));
    vote[shared.component[g]] += side[g] * shared.area[g];
  }
  // Triangles whose corners' lines leave on different sides of the
  // consistent winding.
  auto mixed_triangles = [&](const std::vector<int8_t>& group_side) {
    size_t mixed = 0;
    for (size_t t = 0; t < soup.triangles.size(); ++t) {
      int8_t a = group_side[shared.group_of_corner[3 * t]];
      mixed += a != group_side[shared.group_of_corner[3 * t + 1]] ||
               a != group_side[shared.group_of_corner[3 * t + 2]];
    }
    return mixed;
  };
  const size_t mixed_before = mixed_triangles(side);
  size_t turned = 0;
  for (size_t g = 0; g < groups; ++g) {
    shared.seeds[g].side = probed[g];
    if (!options.orient_sides) continue;
    const int8_t want = vote[shared.component[g]] >= 0 ? 1 : -1;
    if (side[g] == want) continue;
    shared.seeds[g].side = want;
    side[g] = want;
    ++turned;
  }
  field::FieldLines lines = tracer.trace(shared.seeds, progress);
  add_stats(r.trace, tracer.stats());
  r.orient = {{"enabled", options.orient_sides},
              {"shared_lines", true},
              {"components", orientation.components},
              {"flipped_triangles", orientation.flipped_triangles},
              {"conflicting_edges", orientation.conflicting_edges},
              {"adjacent_pairs", adjacency.size()},
              {"turned_sides", turned},
              {"mixed_side_triangles_before", mixed_before},
              {"mixed_side_triangles_after", mixed_triangles(side)}};
  r.trace["shared_lines"] = groups;
  r.trace["corners"] = 3 * soup.triangles.size();
  r.lines = std::move(lines);
  r.line_of_corner = std::move(shared.group_of_corner);
}

// The paper's seeding: one line per corner, from its own triangle.
void trace_per_corner(const Soup& soup, const field::ChargeResult& charges,
                      const field::TraceOptions& trace_options, const FieldBranchOptions& options,
                      Progress& progress, FieldBranchResult& r) {
  // Trace every original corner with the |E| rule, then retrace the corners
  // whose side disagrees with their component's (§12.4).
  std::vector<field::TraceSeed> seeds = field::corner_seeds(soup);
  std::vector<uint32_t> seed_of_corner(3 * soup.triangles.size(), UINT32_MAX);
  for (size_t i = 0; i < seeds.size(); ++i)
    if (seeds[i].corner < seed_of_corner.size()) seed_of_corner[seeds[i].corner] = uint32_t(i);
  field::FieldLineTracer tracer(charges, trace_options);
  progress.update("trace", 0.05);
  field::FieldLines lines = tracer.trace(seeds, progress);
  if (options.orient_sides) {
    auto adjacency = geometry::edge_adjacency(
        geometry::weld_corners(soup, options.weld_tolerance, options.weld_edge_fraction),
        soup.triangles.size());
    field::Orientation orientation = field::consistent_orientation(soup, adjacency);
    field::SideChoice sides = field::component_sides(soup, orientation, lines);
    std::vector<field::TraceSeed> again;
    for (size_t i = 0; i < lines.size(); ++i) {
      uint32_t c = lines.corner[i];
      int want = sides.triangle_side[c / 3];
      if (field::line_side(soup, lines, i) != want && seed_of_corner[c] != UINT32_MAX) {
        field::TraceSeed s = seeds[seed_of_corner[c]];
        s.side = want;
        again.push_back(s);
      }
    }
    retrace(tracer, again, progress, lines);
    r.orient = {{"components", orientation.components},
                {"flipped_triangles", orientation.flipped_triangles},
                {"conflicting_edges", orientation.conflicting_edges},
                {"adjacent_pairs", adjacency.size()},
                {"retraced_corners", again.size()},
                {"mixed_side_triangles_before", sides.mixed_triangles_before},
                {"mixed_side_triangles_after", field::mixed_side_triangles(soup, lines)}};
  } else {
    size_t mixed = field::mixed_side_triangles(soup, lines);
    r.orient = {{"enabled", false},
                {"mixed_side_triangles_before", mixed},
                {"mixed_side_triangles_after", mixed}};
  }
  add_stats(r.trace, tracer.stats());
  r.lines = std::move(lines);
}

}  // namespace

double proxy_reach(const Soup& soup, const proxy::ProxyOptions& options) {
  const double diag = bounding_box(soup).diagonal();
  double ladder = 0;
  for (double f : options.ladder) ladder = std::max(ladder, f * diag);
  if (options.offset_mode == proxy::OffsetMode::automatic) return ladder;
  return std::max(ladder, proxy::absolute_offset(options.offset_mode, options.offset, diag));
}

Box3 stop_box_for(const Soup& soup, double reach) {
  Box3 box = bounding_box(soup);
  const double grow = kReachMargin * reach;
  box.lo = box.lo - Vec3{grow, grow, grow};
  box.hi = box.hi + Vec3{grow, grow, grow};
  return box;
}

FieldBranchResult run_field_branch(const Soup& soup, const std::string& soup_hash,
                                   const FieldBranchOptions& options, cache::Store* cache,
                                   Progress& progress) {
  FieldBranchResult r;
  field::ChargeOptions charge_options = options.charge;
  charge_options.threads = options.threads;
  field::TraceOptions trace_options = options.trace;
  trace_options.threads = options.threads;
  if (options.proxy_reach > 0 && !(trace_options.stop_radius > 0) && trace_options.stop_box.empty()) {
    trace_options.stop_box = stop_box_for(soup, options.proxy_reach);
    // The sphere around the grown box: the tracer's FMM region, never the stop.
    trace_options.stop_radius = 0.5 * trace_options.stop_box.diagonal() * (1 + 1e-9);
  }

  // Charges: cached by the soup, the refinement switch and the charge options.
  const std::string charge_key =
      cache::cache_key({"charges", kFieldCacheVersion, soup_hash,
                        options.refine_intersections ? "refine" : "plain", charge_params(charge_options)});
  // The lines' key: the charges, the trace options and, with a stop
  // surface, that mesh (known only once the caller's proxy exists).
  const std::string trace_key = trace_params(options, trace_options);
  const TriMesh* stop_mesh = nullptr;
  bool stop_asked = false;
  auto stop_surface = [&]() -> const TriMesh* {
    if (!stop_asked && options.stop_surface) stop_mesh = options.stop_surface();
    stop_asked = true;
    return stop_mesh;
  };
  auto lines_key = [&] {
    return cache::cache_key({"lines", kFieldCacheVersion, charge_key, trace_key,
                             stop_surface() ? mesh_hash(*stop_mesh) : std::string("reach")});
  };

  std::shared_ptr<const cache::Bytes> cached_charges;
  // With a stop surface the lines' key must wait for it: only worth it when
  // the charges are cached too (otherwise the wait would delay the solve).
  if (cache && options.stop_surface) cached_charges = cache->get(charge_key);
  if (cache && (!options.stop_surface || cached_charges)) {
    const std::string key = lines_key();
    auto hit = cache->get(key);
    // Shared lines are useless without their corner map (evicted separately).
    auto corners = hit && options.share_lines ? cache->get(key + ".corners") : nullptr;
    if (hit && (corners || !options.share_lines)) {
      // The lines carry everything downstream needs; charges are not even read.
      r.lines = decode_lines(*hit);
      if (corners) {
        cache::ByteReader rd(*corners);
        r.line_of_corner = rd.get_vector<uint32_t>();
      }
      r.lines_cached = r.charges_cached = true;
      if (auto meta = cache->get(key + ".json")) {
        auto j = nlohmann::json::parse(meta->begin(), meta->end());
        r.charge = j["charge"];
        r.trace = j["trace"];
        r.orient = j["orient"];
        r.intersections = j["intersections"];
      }
      r.trace["cached"] = true;
      r.charge["cached"] = true;
      return r;
    }
  }

  field::ChargeResult charges;
  if (cache && !cached_charges) cached_charges = cache->get(charge_key);
  if (cached_charges) {
    charges = decode_charges(*cached_charges);
    r.charges_cached = true;
    if (auto meta = cache->get(charge_key + ".json"))
      r.intersections = nlohmann::json::parse(meta->begin(), meta->end());
  } else {
    auto t0 = std::chrono::steady_clock::now();
    const Soup* charged = &soup;
    field::IntersectionRefinement refinement;
    if (options.refine_intersections) {
      refinement = field::refine_intersections(soup, progress);
      charged = &refinement.soup;
      r.intersections = refinement.diagnostics();
    }
    r.seconds_refine = since(t0);
    r.intersections["seconds"] = r.seconds_refine;
    auto t1 = std::chrono::steady_clock::now();
    charges = field::solve_charges(*charged, charge_options, progress);
    r.seconds_charge = since(t1);
    if (cache) {
      cache->put(charge_key, encode(charges));
      std::string meta = r.intersections.dump();
      cache->put(charge_key + ".json", cache::Bytes(meta.begin(), meta.end()));
    }
  }
  r.charge = charge_json(charges);
  r.charge["cached"] = r.charges_cached;
  r.warnings.insert(r.warnings.end(), charges.warnings.begin(), charges.warnings.end());

  auto t2 = std::chrono::steady_clock::now();
  r.trace = nlohmann::json::object();
  std::unique_ptr<geometry::SurfaceHitBvh> stop_bvh;
  if (stop_surface()) {
    stop_bvh = std::make_unique<geometry::SurfaceHitBvh>(*stop_mesh);
    const geometry::SurfaceHitBvh* bvh = stop_bvh.get();
    // The transfer's own test (land_line): the same segments, the same answer.
    trace_options.stop_crossing = [bvh](Vec3 a, Vec3 b) { return bvh->first_hit(a, b).found(); };
  }
  if (options.share_lines) {
    trace_shared(soup, charges, trace_options, options, progress, r);
  } else {
    trace_per_corner(soup, charges, trace_options, options, progress, r);
  }
  r.seconds_trace = since(t2);
  r.trace["cached"] = false;
  if (cache) {
    const std::string key = lines_key();
    cache->put(key, encode(r.lines));
    nlohmann::json meta = {{"charge", r.charge}, {"trace", r.trace}, {"orient", r.orient},
                           {"intersections", r.intersections}};
    std::string m = meta.dump();
    cache->put(key + ".json", cache::Bytes(m.begin(), m.end()));
    cache::ByteWriter wc;
    wc.put_vector(r.line_of_corner);
    cache->put(key + ".corners", wc.take());
  }
  return r;
}

}  // namespace soupuv::pipeline
