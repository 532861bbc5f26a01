// Field-line tracing (paper §7.6).
//
// Inputs: a ChargeResult (charged source triangles) and seeds; output: one
// polyline per seed (FieldLines). A line starts at v + eps * n (eps: the
// seed's start offset, a fraction of its local edge length) on the side
// where |E| is larger and steps along E/|E| (eq. 10) by explicit Euler or the
// midpoint method. The step shrinks near the surface to a fraction (0.5 ..
// near_step_fraction < 1, larger where the line runs straight) of the
// distance to the nearest near-rule triangle (never below eps), so a line
// cannot jump through a nearby face. Where the line runs straight the step
// may instead grow geometrically (max_step_growth); such a step is kept only
// if the field does not turn too much within it and its segment meets no
// soup triangle, else it is redone at the distance rule. Lines stop outside the stop sphere (or stop_box), at the step
// limit, where |E| vanishes, or when trapped: crawling along the surface at
// the step floor for options.trapped_steps steps in a row.
//
// All lines advance together, one step at a time: every field evaluation of a
// step is one batch, sorted by FMM target leaf, so the points that share a
// leaf share its expansion and near-field data (TracerField). The FMM over the
// sources is built and charged once; a step costs only the target side. Lines
// that stopped drop out of the batch. options.direct evaluates every point by
// direct summation instead (the slow twin).
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "soupuv/errors.h"
#include "soupuv/field/field.h"
#include "soupuv/field/fmm.h"
#include "soupuv/field/sources.h"
#include "soupuv/field/tracer_field.h"
#include "soupuv/field/triangle_integrals.h"
#include "soupuv/geometry/closest_point.h"
#include "soupuv/geometry/segment_triangle.h"

namespace soupuv::field {

std::vector<TraceSeed> corner_seeds(const Soup& soup) {
  std::vector<TraceSeed> seeds;
  seeds.reserve(soup.triangles.size() * 3);
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    Vec3 n = triangle_normal(soup, t);
    Vec3 g = (soup.corner(t, 0) + soup.corner(t, 1) + soup.corner(t, 2)) / 3.0;
    const double scale = triangle_perimeter(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2)) / 3.0;
    for (int k = 0; k < 3; ++k)
      seeds.push_back({soup.corner(t, k), n, 0, static_cast<uint32_t>(t * 3 + k), g, true, scale});
  }
  return seeds;
}

std::vector<TraceSeed> vertex_seeds(const TriMesh& mesh) {
  std::vector<TraceSeed> seeds(mesh.vertices.size());
  std::vector<bool> used(mesh.vertices.size(), false);
  std::vector<int> faces(mesh.vertices.size(), 0);
  for (size_t t = 0; t < mesh.faces.size(); ++t) {
    const auto& f = mesh.faces[t];
    const Vec3 n = cross(mesh.vertices[f[1]] - mesh.vertices[f[0]], mesh.vertices[f[2]] - mesh.vertices[f[0]]);
    const double edge = triangle_perimeter(mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]) / 3.0;
    for (int k = 0; k < 3; ++k) {
      TraceSeed& s = seeds[f[k]];
      if (!used[f[k]]) {
        used[f[k]] = true;
        s.position = mesh.vertices[f[k]];
        s.normal = {0, 0, 0};
        s.corner = static_cast<uint32_t>(t * 3 + k);
      }
      s.normal += n;
      s.scale += edge;
      ++faces[f[k]];
    }
  }
  std::vector<TraceSeed> out;
  for (size_t v = 0; v < seeds.size(); ++v)
    if (used[v]) {
      seeds[v].scale /= faces[v];
      out.push_back(seeds[v]);
    }
  return out;
}

namespace {

using Clock = std::chrono::steady_clock;

// An empty box holds everything (no stop box).
bool outside(const Box3& box, Vec3 p) {
  if (box.empty()) return false;
  return p.x < box.lo.x || p.y < box.lo.y || p.z < box.lo.z || p.x > box.hi.x || p.y > box.hi.y || p.z > box.hi.z;
}

// Sorts keys by their high 32 bits, stably (LSD radix sort, 16-bit digits):
// the keys are built in point order, so points of one leaf stay in order.
// A comparison sort of every batch was a serial step per evaluation round
// while the other threads waited. The upper digit's pass is skipped when no
// key has one (fewer than 65,535 target cells). `count` is the caller's, kept
// between calls (no 256 KB allocation per call).
void sort_by_high_word(std::vector<uint64_t>& keys, std::vector<uint64_t>& scratch, std::vector<uint32_t>& count,
                       bool upper_digit) {
  scratch.resize(keys.size());
  count.resize(1 << 16);
  for (int shift : {32, 48}) {
    if (shift == 48 && !upper_digit) break;
    std::fill(count.begin(), count.end(), 0u);
    for (uint64_t k : keys) ++count[(k >> shift) & 0xffff];
    uint32_t sum = 0;
    for (uint32_t& c : count) {
      const uint32_t here = c;
      c = sum;
      sum += here;
    }
    for (uint64_t k : keys) scratch[count[(k >> shift) & 0xffff]++] = k;
    keys.swap(scratch);
  }
}

// Batches of fewer points run on one thread. A round of a few hundred lines
// is ~1 ms of work, and when the field branch shares the cores with the
// proxy branch every fork/join waits for a descheduled or spinning thread
// (suzanne's corner lines with every round parallel: 3x the wall time on a
// loaded machine). Rounds of a few hundred points and more gain from the
// second thread: the mid-size soups' traces (2,000-4,000 shared lines) ran
// on one thread at the former bound of 4,096, and a large soup's last
// rounds (its slowest lines) at 1,024 (docs/tuning.md, "Time and
// flattening, session 28").
constexpr long kParallelMinPoints = 512;

// Field at a batch of points: E[i] (overwritten) and, when `nearest` is given,
// the distance to the nearest near-rule triangle. `leaf` caches each point's
// target leaf between calls (a point usually stays in or near its leaf).
class BatchField {
 public:
  BatchField(const SourceGeometry& src, const std::vector<double>& charges, const TraceOptions& o,
             Box3 region, int threads)
      : src_(src), charges_(charges), direct_(o.direct), threads_(threads) {
    if (direct_) return;
    FmmOptions fo;
    fo.order = o.fmm_order;
    fo.theta = o.fmm_theta;
    fo.threads = threads;
    fo.leaf_size = o.fmm_leaf_size;
    // Trees and interaction lists only: TracerField computes the multipoles
    // itself and local expansions only where tracers go.
    fmm_ = std::make_unique<Fmm>(src, fo, region);
    tracer_ = std::make_unique<TracerField>(*fmm_, charges, threads);
  }

  void evaluate(const std::vector<Vec3>& x, std::vector<int>& leaf, std::vector<Vec3>& E,
                std::vector<double>* nearest) {
    const long n = static_cast<long>(x.size());
    if (direct_) {
      E.assign(n, Vec3{0, 0, 0});
      if (nearest) nearest->assign(n, std::numeric_limits<double>::infinity());
      return evaluate_direct(x, E, nearest);
    }
    // Every point belongs to one chunk below, which writes its E and nearest.
    E.resize(n);
    if (nearest) nearest->resize(n);
    const int nth = n >= kParallelMinPoints ? threads_ : 1;
    // Sort by leaf (key: leaf in the high bits, point in the low) and cut the
    // runs into chunks small enough to balance the threads.
    keys_.resize(n);
    uint64_t top = 0;
#pragma omp parallel for num_threads(nth) schedule(static) reduction(max : top)
    for (long i = 0; i < n; ++i) {
      leaf[i] = tracer_->locate(x[i], leaf[i]);
      keys_[i] = (static_cast<uint64_t>(static_cast<uint32_t>(leaf[i] + 1)) << 32) | static_cast<uint32_t>(i);
      top = std::max(top, keys_[i] >> 48);
    }
    sort_by_high_word(keys_, scratch_, count_, top > 0);
    constexpr long kChunk = 32;
    chunks_.clear();
    leaves_.clear();
    for (long s = 0; s < n;) {
      long e = s + 1;
      while (e < n && e - s < kChunk && (keys_[e] >> 32) == (keys_[s] >> 32)) ++e;
      chunks_.push_back({s, e});
      const int lf = static_cast<int>(keys_[s] >> 32) - 1;
      if (lf >= 0 && (leaves_.empty() || leaves_.back() != lf)) leaves_.push_back(lf);
      s = e;
    }
    tracer_->prepare(leaves_);
    const long nc = static_cast<long>(chunks_.size());
#pragma omp parallel num_threads(nth)
    {
      std::vector<Vec3> xs, es;
      std::vector<double> ds;
#pragma omp for schedule(dynamic, 4)
      for (long c = 0; c < nc; ++c) {
        const auto [s, e] = chunks_[c];
        const int cnt = static_cast<int>(e - s);
        xs.resize(cnt);
        es.assign(cnt, Vec3{0, 0, 0});
        ds.resize(cnt);
        for (int k = 0; k < cnt; ++k) xs[k] = x[keys_[s + k] & 0xffffffffu];
        const int lf = static_cast<int>(keys_[s] >> 32) - 1;
        tracer_->field(lf, xs.data(), cnt, es.data(), nearest ? ds.data() : nullptr);
        for (int k = 0; k < cnt; ++k) {
          const size_t i = keys_[s + k] & 0xffffffffu;
          E[i] = es[k];
          if (nearest) (*nearest)[i] = ds[k];
        }
      }
    }
  }

  // True when segment ab meets a soup triangle.
  bool segment_crosses(Vec3 a, Vec3 b) const {
    if (fmm_) return fmm_->segment_crosses(a, b);
    for (size_t j = 0; j < src_.size(); ++j)
      if (geometry::segment_crosses_triangle(a, b, src_.a[j], src_.b[j], src_.c[j])) return true;
    return false;
  }

  // Local expansions computed and M2L operations spent so far (0 for direct).
  size_t expansions() const { return tracer_ ? tracer_->expansions() : 0; }
  size_t m2l_operations() const { return tracer_ ? tracer_->m2l_operations() : 0; }
  size_t m2l_terms() const { return tracer_ ? tracer_->m2l_terms() : 0; }

 private:
  void evaluate_direct(const std::vector<Vec3>& x, std::vector<Vec3>& E, std::vector<double>* nearest) const {
    const long n = static_cast<long>(x.size());
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 4)
    for (long i = 0; i < n; ++i) {
      Vec3 e{0, 0, 0};
      double best = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < src_.size(); ++j) {
        Vec3 ej{0, 0, 0};
        unit_potential_field(src_, j, x[i], nullptr, &ej);
        e += charges_[j] * ej;
        if (nearest && src_.area[j] > 0 && src_.is_near(j, x[i]))
          best = std::min(best, geometry::point_triangle_distance(x[i], src_.a[j], src_.b[j], src_.c[j]));
      }
      E[i] = e;
      if (nearest) (*nearest)[i] = best;
    }
  }

  const SourceGeometry& src_;
  const std::vector<double>& charges_;
  bool direct_;
  int threads_;
  std::unique_ptr<Fmm> fmm_;
  std::unique_ptr<TracerField> tracer_;
  std::vector<uint64_t> keys_, scratch_;
  std::vector<uint32_t> count_;
  std::vector<std::pair<long, long>> chunks_;
  std::vector<int> leaves_;
};

}  // namespace

struct FieldLineTracer::Impl {
  Impl(const ChargeResult& charges, const TraceOptions& o)
      : options(o), t0(Clock::now()), src(sources_of(charges, o)) {
    Box3 box;
    double edge_sum = 0;
    for (size_t j = 0; j < src.size(); ++j) {
      box.add(src.a[j]); box.add(src.b[j]); box.add(src.c[j]);
      edge_sum += triangle_perimeter(src.a[j], src.b[j], src.c[j]);
    }
    center = box.center();
    const double diag = box.diagonal();
    step = o.step > 0 ? o.step : 0.02 * diag;
    mean_edge = edge_sum / (3.0 * src.size());
    stop_radius = o.stop_radius > 0 ? o.stop_radius : diag;  // twice the half diagonal
    stalled_field = 1e-9 / (diag * diag);  // total charge is 1
    nth = o.threads > 0 ? o.threads : omp_get_max_threads();
    Box3 region;
    region.add(center - Vec3{stop_radius, stop_radius, stop_radius});
    region.add(center + Vec3{stop_radius, stop_radius, stop_radius});
    field = std::make_unique<BatchField>(src, charges.charges, o, region, nth);
    build_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  }

  // Validates the charges and options; the charged triangles as sources.
  static SourceGeometry sources_of(const ChargeResult& charges, const TraceOptions& o) {
    if (charges.charges.size() != charges.triangles.size())
      throw Error(ErrorCode::invalid_input, "trace: charges do not match the source triangles");
    // A step of at least the nearest triangle's distance could reach it.
    if (!(o.near_step_fraction > 0 && o.near_step_fraction < 1))
      throw Error(ErrorCode::invalid_input, "trace: near_step_fraction must lie in (0, 1)");
    if (!(o.max_step_growth == 0 || (o.max_step_growth >= 1 && o.max_step_growth <= 1e3)))
      throw Error(ErrorCode::invalid_input, "trace: max_step_growth must be 0 or lie in [1, 1000]");
    return make_sources(charges.positions, charges.triangles, charges.quadrature_degree);
  }

  // Unit normals of the seeds (a zero normal: away from the centre).
  std::vector<Vec3> unit_normals(const std::vector<TraceSeed>& seeds) const {
    std::vector<Vec3> nrm(seeds.size());
    for (size_t s = 0; s < seeds.size(); ++s) {
      Vec3 v = normalized(seeds[s].normal);
      if (norm2(v) == 0) v = normalized(seeds[s].position - center);
      if (norm2(v) == 0) v = {0, 0, 1};
      nrm[s] = v;
    }
    return nrm;
  }

  // Side choice: probe both sides of every side-0 seed in one batch. The
  // probe moves slightly towards the seed's interior point (see TraceSeed).
  std::vector<int> probe(const std::vector<TraceSeed>& seeds, const std::vector<Vec3>& nrm) {
    const long n = static_cast<long>(seeds.size());
    std::vector<int> side(n);
    std::vector<long> probed;
    for (long s = 0; s < n; ++s) {
      side[s] = seeds[s].side;
      if (side[s] == 0) probed.push_back(s);
    }
    if (probed.empty()) return side;
    const size_t np = probed.size();
    std::vector<Vec3> X(2 * np), E;
    for (size_t k = 0; k < np; ++k) {
      const TraceSeed& seed = seeds[probed[k]];
      Vec3 base = seed.position;
      if (seed.has_interior) base = base + 0.05 * (seed.interior - seed.position);
      const double eps = start_offset(seed);
      X[k] = base + eps * nrm[probed[k]];
      X[np + k] = base - eps * nrm[probed[k]];
    }
    std::vector<int> leaf(X.size(), -1);
    field->evaluate(X, leaf, E, nullptr);
    evaluations += X.size();
    for (size_t k = 0; k < np; ++k) side[probed[k]] = norm2(E[k]) >= norm2(E[np + k]) ? 1 : -1;
    return side;
  }

  FieldLines trace(const std::vector<TraceSeed>& seeds, Progress& progress);

  // Epsilon of one seed (TraceOptions::start_offset).
  double start_offset(const TraceSeed& seed) const {
    if (options.start_offset > 0) return options.start_offset;
    return options.start_offset_fraction * (seed.scale > 0 ? seed.scale : mean_edge);
  }

  const TraceOptions options;
  const Clock::time_point t0;
  const SourceGeometry src;
  Vec3 center;
  double step = 0, mean_edge = 0, stop_radius = 0, stalled_field = 0, build_seconds = 0;
  int nth = 1;
  std::unique_ptr<BatchField> field;
  // Totals over every probe and trace (TraceStats).
  size_t evaluations = 0, steps_total = 0, grown_steps = 0, grown_redone = 0;
  size_t escaped = 0, step_limit = 0, stalled = 0, trapped = 0, reached = 0;
};

FieldLineTracer::FieldLineTracer(const ChargeResult& charges, const TraceOptions& options)
    : impl_(std::make_unique<Impl>(charges, options)) {}

FieldLineTracer::~FieldLineTracer() = default;

std::vector<int> FieldLineTracer::probe_sides(const std::vector<TraceSeed>& seeds) {
  return impl_->probe(seeds, impl_->unit_normals(seeds));
}

FieldLines FieldLineTracer::trace(const std::vector<TraceSeed>& seeds, Progress& progress) {
  return impl_->trace(seeds, progress);
}

TraceStats FieldLineTracer::stats() const {
  const Impl& m = *impl_;
  TraceStats st;
  st.seconds = std::chrono::duration<double>(Clock::now() - m.t0).count();
  st.build_seconds = m.build_seconds;
  st.evaluations = m.evaluations;
  st.steps = m.steps_total;
  st.expansions = m.field->expansions();
  st.m2l_operations = m.field->m2l_operations();
  st.m2l_terms = m.field->m2l_terms();
  st.grown_steps = m.grown_steps;
  st.grown_steps_redone = m.grown_redone;
  st.escaped = m.escaped;
  st.step_limit = m.step_limit;
  st.stalled = m.stalled;
  st.trapped = m.trapped;
  st.reached = m.reached;
  return st;
}

FieldLines trace_field_lines(const ChargeResult& charges, const std::vector<TraceSeed>& seeds,
                             const TraceOptions& options, Progress& progress, TraceStats* stats) {
  FieldLineTracer tracer(charges, options);
  progress.update("trace", 0.05);
  FieldLines lines = tracer.trace(seeds, progress);
  if (stats) *stats = tracer.stats();
  return lines;
}

FieldLines FieldLineTracer::Impl::trace(const std::vector<TraceSeed>& seeds, Progress& progress) {
  if (seeds.size() >= (size_t{1} << 32))
    throw Error(ErrorCode::limit_exceeded, "trace: too many seeds");
  const bool midpoint = options.integrator == TraceOptions::Integrator::midpoint;
  BatchField& field = *this->field;
  const long n = static_cast<long>(seeds.size());
  const std::vector<Vec3> nrm = unit_normals(seeds);
  const std::vector<int> side = probe(seeds, nrm);
  std::vector<Vec3> X, E, Ep;
  std::vector<int> leaf, leaf_p;

  std::vector<std::vector<Vec3>> lines(n);
  std::vector<LineEnd> ends(n, LineEnd::step_limit);
  std::vector<long> active(n);
  std::vector<Vec3> pos(n);
  std::vector<double> eps(n);  // per line: its seed's start offset
  std::vector<int> line_leaf(n, -1);
  for (long s = 0; s < n; ++s) {
    active[s] = s;
    eps[s] = start_offset(seeds[s]);
    pos[s] = seeds[s].position + (side[s] * eps[s]) * nrm[s];
    lines[s].push_back(seeds[s].position);
    lines[s].push_back(pos[s]);
  }
  std::vector<double> nearest, h;
  std::vector<uint8_t> keep;
  // Trapped lines (options.trapped_steps): per line, how many steps in a row
  // it has been within 2 eps of the soup (where the step is the floor eps).
  const bool detect_trapped = options.adaptive_step && options.trapped_steps > 0;
  std::vector<int> crawl(n, 0);
  // Per line, the direction of E at its last step's start and that step's
  // length (0: no step yet): the line's curvature for the step rule.
  std::vector<Vec3> last_dir(n, Vec3{0, 0, 0});
  std::vector<double> last_h(n, 0.0);
  const double max_fraction = options.near_step_fraction;
  const double min_fraction = std::min(0.5, max_fraction);
  // Grown steps need the midpoint's field to be checked (below): with
  // explicit Euler the distance rule alone applies.
  const double growth = midpoint && options.adaptive_step ? options.max_step_growth : 0.0;
  const bool grow = growth > 0;
  // The near-surface step of line s at a point with field e and nearest
  // near-rule triangle at distance d (see TraceOptions::near_step_fraction
  // and max_step_growth): turn per step ~ curvature * h, the curvature from
  // the change of E's direction over the line's previous step.
  auto near_step = [&](long s, Vec3 e, double d) {
    if (!(last_h[s] > 0) || !(d < std::numeric_limits<double>::infinity())) return min_fraction * d;
    // Within 2 eps the step stays at its floor (the trapped rule,
    // TraceOptions::trapped_steps, counts crawling steps there); the larger
    // reach ramps in up to 4 eps: a step rule that jumps would let the
    // last digits of E pick between two step lengths.
    const double ramp = std::clamp((d - 2 * eps[s]) / (2 * eps[s]), 0.0, 1.0);
    double reach = max_fraction * d;
    if (growth > 0) reach = std::max(reach, std::min(step, growth * last_h[s]));
    const double upper = min_fraction * d + ramp * (reach - min_fraction * d);
    const double curvature = norm(e / norm(e) - last_dir[s]) / last_h[s];
    const double h = curvature > 0 ? options.max_turn_per_step / curvature : upper;
    return std::clamp(h, min_fraction * d, upper);
  };
  // Steps longer than max_fraction * d (grown steps) are checked once the
  // midpoint's field is known (below); `safe_h` is the length they fall
  // back to (the distance rule's bound), 0 for steps that need no check.
  std::vector<double> safe_h;
  std::vector<long> redo;
  for (int k = 0; k < options.max_steps && !active.empty(); ++k) {
    // The share of lines ended, or of steps taken if more: the step count
    // alone stood at a sixth of the bar when table-exact's trace ended
    // (its lines end within ~17 of the 100 steps) and jumped from there.
    const double ended = n > 0 ? 1.0 - double(active.size()) / double(n) : 1.0;
    progress.update("trace", 0.05 + 0.9 * std::max(ended, k / double(options.max_steps)));
    const size_t na = active.size();
    const long nal = static_cast<long>(na);
    // The per-line loops of a step run on the threads too: serial, they were
    // a few ms per step at 100k lines while the other threads waited.
    const int step_threads = nal >= kParallelMinPoints ? nth : 1;
    X.resize(na);
    leaf.resize(na);
#pragma omp parallel for num_threads(step_threads) schedule(static)
    for (long a = 0; a < nal; ++a) {
      X[a] = pos[active[a]];
      leaf[a] = line_leaf[active[a]];
    }
    field.evaluate(X, leaf, E, options.adaptive_step ? &nearest : nullptr);
    evaluations += na;
    // Step lengths; a line whose field vanished stops here (h = 0 marks it).
    // Buffers are sized, not cleared, here: every loop writes each entry.
    h.resize(na);
    if (grow) safe_h.assign(na, 0.0);
#pragma omp parallel for num_threads(step_threads) schedule(static)
    for (long a = 0; a < nal; ++a) {
      h[a] = 0;
      line_leaf[active[a]] = leaf[a];
      if (!(norm(E[a]) > stalled_field)) {
        ends[active[a]] = LineEnd::stalled;
        continue;
      }
      const long s = active[a];
      h[a] = options.adaptive_step ? std::min(step, std::max(eps[s], near_step(s, E[a], nearest[a]))) : step;
      if (grow) {
        const double bound = std::min(step, std::max(eps[s], max_fraction * nearest[a]));
        safe_h[a] = h[a] > bound ? bound : 0.0;
      }
      if (!detect_trapped) continue;
      crawl[s] = nearest[a] < 2 * eps[s] ? crawl[s] + 1 : 0;
      if (crawl[s] >= options.trapped_steps) {
        ends[s] = LineEnd::trapped;
        h[a] = 0;
      }
    }
    // E keeps the field at the step's start (the line's direction for the
    // step rule); the midpoint's field goes to Ep and moves the line.
    if (midpoint) {
      leaf_p.resize(na);
#pragma omp parallel for num_threads(step_threads) schedule(static)
      for (long a = 0; a < nal; ++a) {
        if (h[a] > 0) X[a] = X[a] + (0.5 * h[a] / norm(E[a])) * E[a];
        leaf_p[a] = leaf[a];
      }
      field.evaluate(X, leaf_p, Ep, nullptr);
      evaluations += na;
#pragma omp parallel for num_threads(step_threads) schedule(static)
      for (long a = 0; a < nal; ++a) {
        if (!(h[a] > 0)) continue;
        if (!(norm(Ep[a]) > stalled_field)) {
          ends[active[a]] = LineEnd::stalled;
          h[a] = 0;
        }
      }
    }
    const std::vector<Vec3>& Emove = midpoint ? Ep : E;
    // A grown step is redone at the distance rule's length (the midpoint's
    // field evaluated again) when the field turned by more than the turn
    // limit between its start and its midpoint (the curvature it was sized
    // by was an estimate from the previous, shorter step), or when its
    // segment meets the soup.
    if (grow) {
      redo.clear();
      size_t grown = 0;
#pragma omp parallel for num_threads(step_threads) schedule(dynamic, 256) reduction(+ : grown)
      for (long a = 0; a < nal; ++a) {
        if (!(h[a] > 0) || !(safe_h[a] > 0)) continue;
        ++grown;
        const Vec3 p0 = pos[active[a]];
        const double turn = norm(Ep[a] / norm(Ep[a]) - E[a] / norm(E[a]));
        if (!(turn > options.max_turn_per_step) &&
            !field.segment_crosses(p0, p0 + (h[a] / norm(Ep[a])) * Ep[a]))
          continue;
#pragma omp critical(trace_redo)
        redo.push_back(a);
      }
      grown_steps += grown;
      grown_redone += redo.size();
      if (!redo.empty()) {
        std::sort(redo.begin(), redo.end());
        for (long a : redo) h[a] = safe_h[a];
        std::vector<Vec3> Xr(redo.size()), Er;
        std::vector<int> leaf_r(redo.size());
        for (size_t r = 0; r < redo.size(); ++r) {
          const long a = redo[r];
          Xr[r] = pos[active[a]] + (0.5 * h[a] / norm(E[a])) * E[a];
          leaf_r[r] = leaf[a];
        }
        field.evaluate(Xr, leaf_r, Er, nullptr);
        evaluations += redo.size();
        for (size_t r = 0; r < redo.size(); ++r) {
          const long a = redo[r];
          Ep[a] = Er[r];
          if (!(norm(Ep[a]) > stalled_field)) {
            ends[active[a]] = LineEnd::stalled;
            h[a] = 0;
          }
        }
      }
    }
    // Move the lines (in parallel), then keep the active ones in order (serial, cheap).
    keep.resize(na);
    size_t stepped = 0;
#pragma omp parallel for num_threads(step_threads) schedule(static) reduction(+ : stepped)
    for (long a = 0; a < nal; ++a) {
      const long s = active[a];
      keep[a] = 0;
      if (!(h[a] > 0)) continue;  // stalled or trapped
      last_dir[s] = E[a] / norm(E[a]);
      last_h[s] = h[a];
      const Vec3 from = pos[s];
      pos[s] = pos[s] + (h[a] / norm(Emove[a])) * Emove[a];
      ++stepped;
      if (options.keep_points) lines[s].push_back(pos[s]);
      if (options.stop_crossing && options.stop_crossing(from, pos[s])) {
        ends[s] = LineEnd::reached;
        continue;
      }
      if (norm(pos[s] - center) > stop_radius || outside(options.stop_box, pos[s])) {
        ends[s] = LineEnd::escaped;
        continue;
      }
      keep[a] = 1;
    }
    steps_total += stepped;
    size_t kept = 0;
    for (size_t a = 0; a < na; ++a)
      if (keep[a]) active[kept++] = active[a];
    active.resize(kept);
  }
  FieldLines out;
  size_t total = 0;
  for (long s = 0; s < n; ++s) {
    if (!options.keep_points) lines[s].push_back(pos[s]);
    total += lines[s].size();
  }
  out.points.reserve(total);
  out.offsets.reserve(n + 1);
  for (long s = 0; s < n; ++s) {
    out.points.insert(out.points.end(), lines[s].begin(), lines[s].end());
    out.offsets.push_back(static_cast<uint32_t>(out.points.size()));
    out.corner.push_back(seeds[s].corner);
  }
  out.ends = std::move(ends);
  for (LineEnd e : out.ends) {
    if (e == LineEnd::escaped) ++escaped;
    else if (e == LineEnd::step_limit) ++step_limit;
    else if (e == LineEnd::stalled) ++stalled;
    else if (e == LineEnd::reached) ++reached;
    else ++trapped;
  }
  progress.update("trace", 1.0);
  return out;
}

}  // namespace soupuv::field
