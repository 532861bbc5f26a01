// The tracer's batched field evaluator (see tracer_field.h).
#include "soupuv/field/tracer_field.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "soupuv/field/quadrature.h"
#include "soupuv/field/sources.h"
#include "soupuv/field/triangle_integrals.h"
#include "soupuv/geometry/closest_point.h"
#include "tracer_closed_form.h"
#include "tracer_closed_form_batch.h"
#include "tracer_kernels.h"
#include "tracer_l2p.h"
#include "tracer_m2l.h"

namespace soupuv::field {

// What the near rule needs of one triangle, in tree order (the candidates of
// a source leaf are contiguous) and with its closed-form frame precomputed.
struct TracerField::NearTriangle {
  tracer::TriangleFrame frame;
  double area = 0;
};
// Apart from the frame (which only evaluated candidates read), so that
// classifying a point's candidates touches one cache line per triangle.
struct TracerField::NearTest {
  Vec3 centroid;
  double radius = 0;
  double near2 = 0;               // squared radius of SourceGeometry::is_near
  double whole2 = 0, split2 = 0;  // squared radii of the bands above (kWholeFactor, kSplitFactor)
  bool has_area = false;
};

TracerField::~TracerField() = default;

// The near triangles of one point that take a float rule, collected so the
// kernel sums them eight at a time (tracer::rule_field_batch), and those that
// take the closed form, four at a time.
struct TracerField::RuleBatch {
  tracer::RuleTriangles mid, split;  // the degree-6 rule; the same on the four midpoint children
  tracer::ClosedFormBatch closed;

  void add(bool whole, Vec3 x, const tracer::TriangleFrame& f, double q, double* e) {
    float v[3][3];
    for (int k = 0; k < 3; ++k) {
      const Vec3 d = f.v[k] - x;
      v[k][0] = static_cast<float>(d.x);
      v[k][1] = static_cast<float>(d.y);
      v[k][2] = static_cast<float>(d.z);
    }
    tracer::RuleTriangles& t = whole ? mid : split;
    if (t.add(v[0], v[1], v[2], static_cast<float>(q)))
      tracer::rule_field_batch(whole ? tracer::degree6_rule() : tracer::degree6_children_rule(), t, e);
  }
  void flush(double* e) {
    tracer::rule_field_batch(tracer::degree6_rule(), mid, e);
    tracer::rule_field_batch(tracer::degree6_children_rule(), split, e);
    closed.flush(e);
  }
};

namespace {

Vec3 scalar_sum(const Vec3* p, const double* q, int n, Vec3 x) {
  Vec3 e{0, 0, 0};
  for (int k = 0; k < n; ++k) {
    const Vec3 d = x - p[k];
    const double inv = 1.0 / std::sqrt(norm2(d));
    e += (q[k] * inv * inv * inv) * d;
  }
  return e;
}

void to_float(Vec3 v, float* f) {
  f[0] = static_cast<float>(v.x);
  f[1] = static_cast<float>(v.y);
  f[2] = static_cast<float>(v.z);
}

}  // namespace

// The model (sources.h) takes the closed form within closed_factor (2.5)
// radii of a triangle's centroid and the degree-6 rule from there to
// near_factor (4) radii, where the triangle's own degree-4 rule takes over.
// Its worst per-triangle field error is that of the degree-4 rule at 4 radii:
// 1.9e-5 relative (measured over directions in and off the plane, equilateral
// to sliver triangles). The tracer spends up to the same per-triangle error
// for speed, so the model's worst error does not grow:
//  - from kWholeFactor (2.25) radii on, the degree-6 rule on the triangle
//    (worst 1.84e-5 at 2.25 radii; 7.3e-6 at 2.5);
//  - from kSplitFactor (1.55) radii, the degree-6 rule on the triangle's four
//    midpoint children: a child has half the radius and its centroid lies
//    within r/2 of the parent's, so every child is at least 2.1 of its own
//    radii away (worst 1.64e-5 at 1.55 radii);
//  - the closed form (three logs, one atan2; four triangles per AVX2 pass,
//    tracer_closed_form_batch.h) only below.
// Session 6 had 2.5 and 1.75 (worst 7.3e-6 and 3.4e-6). Near a surface the
// candidates in a band grow with its area: ~22 % fewer closed forms and ~17 %
// fewer 48-point children rules, each band's rest now 12 points.
constexpr double kWholeFactor = 2.25;
constexpr double kSplitFactor = 1.55;

int TracerField::m2l_order_for(double rho, double theta, int p) {
  const int lowest = std::min(2, p);
  if (!(rho < theta)) return p;
  if (!(rho > 0)) return lowest;
  const int q = static_cast<int>(std::ceil((p + 1) * std::log(theta) / std::log(rho) - 1e-9));
  return std::clamp(q, lowest, p);
}

TracerField::TracerField(const Fmm& fmm, const std::vector<double>& charges, int threads, M2lOrder m2l_order)
    : fmm_(fmm),
      m_(fmm.src_.points_per_triangle),
      threads_(threads > 0 ? threads : omp_get_max_threads()),
      ncoef_(fmm.ncoef_),
      field_expansion_(std::make_unique<tracer::FieldExpansion>(fmm.basis_)),
      m2l_order_(m2l_order) {
  const int p = fmm.basis_.order();
  m2l_by_order_.resize(p + 1);
  for (int q = m2l_order == M2lOrder::full ? p : std::min(2, p); q <= p; ++q)
    m2l_by_order_[q] = std::make_unique<tracer::BatchM2L>(q == p ? fmm.basis_ : TaylorBasis(q));
  const SourceGeometry& src = fmm.src_;
  const size_t n = fmm.order_.size();
  pq_.resize(n * m_);
  tri_charge_.resize(n);
  // The per-triangle and per-leaf set-up below runs in parallel: at 204,800
  // triangles it was a serial part of the trace's build.
  const long nl = static_cast<long>(n);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (long k = 0; k < nl; ++k) {
    const double q = charges[fmm.order_[k]];
    tri_charge_[k] = q;
    for (int i = 0; i < m_; ++i) pq_[k * m_ + i] = q * src.qweights[i];
  }
  near_tris_.resize(n);
  near_test_.resize(n);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (long k = 0; k < nl; ++k) {
    const uint32_t j = fmm.order_[k];
    near_tris_[k].frame = tracer::triangle_frame(src.a[j], src.b[j], src.c[j]);
    near_tris_[k].area = src.area[j];
    NearTest& t = near_test_[k];
    t.centroid = src.centroid[j];
    t.radius = src.radius[j];
    t.has_area = src.area[j] > 0;
    // Computed as SourceGeometry::is_near does, so the tests agree bit for bit.
    const double rn = src.near_factor * src.radius[j];
    t.near2 = rn * rn;
    // Never beyond the model's own closed-form zone (a model with a smaller closed_factor).
    const double whole = std::min(kWholeFactor, src.closed_factor), split = std::min(kSplitFactor, whole);
    t.whole2 = whole * whole * src.radius[j] * src.radius[j];
    t.split2 = split * split * src.radius[j] * src.radius[j];
  }
  // Float blocks (tracer_kernels.h): the leaf children of each source cell
  // back to back (a leaf without a parent, the root, alone), relative to that
  // cell's expansion centre. Leaves at the tree's depth limit may be larger
  // than leaf_size; nothing here depends on the size.
  const int gf = tracer::group_floats(m_);
  const auto& cells = fmm.scells_;
  span_of_cell_.assign(cells.size(), -1);
  auto add_block = [&](Vec3 mc) {
    Block b;
    b.mc = mc;
    b.block = block_list_.empty() ? 0 : block_list_.back().block + static_cast<size_t>(block_list_.back().groups) * gf;
    b.slot0 = block_list_.empty() ? 0 : block_list_.back().slot0 + static_cast<size_t>(block_list_.back().groups) * tracer::kLanes;
    block_list_.push_back(b);
  };
  auto add_leaf = [&](int ci, int slot) {
    Span s;
    s.block = static_cast<int>(block_list_.size()) - 1;
    s.first_slot = slot;
    s.count = cells[ci].count;
    span_of_cell_[ci] = static_cast<int>(spans_.size());
    spans_.push_back(s);
    return slot + s.count;
  };
  if (!cells.empty() && cells[0].children == 0) {
    add_block(cells[0].mc);
    block_list_.back().groups = (add_leaf(0, 0) + tracer::kLanes - 1) / tracer::kLanes;
  }
  for (size_t ci = 0; ci < cells.size(); ++ci) {
    const auto& cell = cells[ci];
    if (cell.children == 0) continue;
    int slots = 0;
    for (int k = 0; k < cell.children; ++k)
      if (cells[cell.child_first + k].children == 0) {
        if (slots == 0) add_block(cell.mc);
        slots = add_leaf(cell.child_first + k, slots);
      }
    if (slots > 0) block_list_.back().groups = (slots + tracer::kLanes - 1) / tracer::kLanes;
  }
  size_t total_groups = 0;
  for (const Block& b : block_list_) total_groups += b.groups;
  blocks_.assign(total_groups * gf, 0.0f);
  slot_tri_.assign(total_groups * tracer::kLanes, -1);
  for (size_t ci = 0; ci < cells.size(); ++ci) {
    if (span_of_cell_[ci] < 0) continue;
    const Span& s = spans_[span_of_cell_[ci]];
    const size_t s0 = block_list_[s.block].slot0 + s.first_slot;
    for (int i = 0; i < s.count; ++i) slot_tri_[s0 + i] = cells[ci].first + i;
  }
  const long nb = static_cast<long>(block_list_.size());
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (long bi = 0; bi < nb; ++bi) {
    const Block& blk = block_list_[bi];
    for (int g = 0; g < blk.groups; ++g) {
      float* b = &blocks_[blk.block + static_cast<size_t>(g) * gf];
      for (int l = 0; l < tracer::kLanes; ++l) {
        const int k = slot_tri_[blk.slot0 + static_cast<size_t>(g) * tracer::kLanes + l];
        const bool real = k >= 0;
        // Padding: never near, no charge, points well away from any target.
        const Vec3 c = real ? src.centroid[fmm.order_[k]] - blk.mc : Vec3{1e6, 1e6, 1e6};
        const double nr = real ? src.near_factor * src.radius[fmm.order_[k]] : -1.0;
        b[l] = static_cast<float>(c.x);
        b[8 + l] = static_cast<float>(c.y);
        b[16 + l] = static_cast<float>(c.z);
        b[24 + l] = real ? static_cast<float>(nr * nr) : -1.0f;
        for (int i = 0; i < m_; ++i) {
          float* p = b + 32 + 32 * i;
          const Vec3 y = real ? fmm.points_[static_cast<size_t>(k) * m_ + i] - blk.mc : Vec3{1e6, 1e6, 1e6};
          p[l] = static_cast<float>(y.x);
          p[8 + l] = static_cast<float>(y.y);
          p[16 + l] = static_cast<float>(y.z);
          p[24 + l] = real ? static_cast<float>(pq_[static_cast<size_t>(k) * m_ + i]) * tracer::kChargeScale : 0.0f;
        }
      }
    }
  }
  upward_pass();
  slot_.assign(fmm.tcells_.size(), -1);
  plans_.resize(fmm.tcells_.size());
}

// P2M at the source leaves, M2M up the tree, level by level (deepest first).
void TracerField::upward_pass() {
  const auto& cells = fmm_.scells_;
  std::vector<std::vector<int>> levels;
  for (size_t ci = 0; ci < cells.size(); ++ci) {
    if (static_cast<int>(levels.size()) <= cells[ci].level) levels.resize(cells[ci].level + 1);
    levels[cells[ci].level].push_back(static_cast<int>(ci));
  }
  M_.assign(cells.size() * ncoef_, 0.0);
  for (int level = static_cast<int>(levels.size()) - 1; level >= 0; --level) {
    const auto& ids = levels[level];
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 8)
    for (long i = 0; i < static_cast<long>(ids.size()); ++i) {
      const auto& c = cells[ids[i]];
      double* M = &M_[static_cast<size_t>(ids[i]) * ncoef_];
      if (c.children == 0) {
        const size_t p0 = static_cast<size_t>(c.first) * m_;
        fmm_.basis_.p2m(c.mc, &fmm_.points_[p0], &pq_[p0], c.count * m_, M);
      } else {
        for (int k = 0; k < c.children; ++k) {
          const int ch = c.child_first + k;
          fmm_.basis_.m2m(&M_[static_cast<size_t>(ch) * ncoef_], cells[ch].mc - c.mc, M);
        }
      }
    }
  }
}

void TracerField::prepare(const std::vector<int>& leaves) {
  // Missing cells: each leaf and its ancestors up to the first computed one.
  // Slot -2 marks a cell already collected.
  std::vector<int> todo;
  for (int leaf : leaves) {
    for (int c = leaf; c >= 0 && slot_[c] == -1; c = fmm_.tcells_[c].parent) {
      slot_[c] = -2;
      todo.push_back(c);
    }
  }
  if (todo.empty()) return;
  // Parents before children: by level, then one parallel pass per level.
  std::sort(todo.begin(), todo.end(),
            [&](int a, int b) { return fmm_.tcells_[a].level < fmm_.tcells_[b].level; });
  for (int c : todo) slot_[c] = static_cast<int>(slots_++);
  slot_doubles_ = ncoef_ + field_expansion_->size();
  // Uninitialised (new double[], not a vector): each slot is written below.
  while (pages_.size() * kPageSlots < slots_) pages_.emplace_back(new double[kPageSlots * slot_doubles_]);
  // The M2Ls (most of the cost) do not depend on the parent: all missing
  // cells at once, in one parallel pass. Per level, the small levels of a
  // round ran on one thread while the other waited (a 2-thread profile at
  // 12,800 had 5.2 % of the samples in M2L on the master, 3.5 % on the other).
  size_t ops = 0, terms = 0;
  const long nt = static_cast<long>(todo.size());
  const int p = fmm_.basis_.order();
  const double theta = fmm_.opt_.theta;
  // A round of a few cells is not worth a fork/join (see trace.cpp).
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1) reduction(+ : ops, terms) if (nt >= 32)
  for (long i = 0; i < nt; ++i) {
    const int c = todo[i];
    const auto& cell = fmm_.tcells_[c];
    double* L = local(slot_[c]);
    std::fill_n(L, ncoef_, 0.0);
    const auto& sources = fmm_.m2l_[c];
    // The sources grouped by their order (a counting sort), one batched call per order.
    const double r_target = cell.half * std::sqrt(3.0);
    std::vector<int> order_of(sources.size());
    std::vector<int> first(p + 2, 0);
    for (size_t k = 0; k < sources.size(); ++k) {
      const auto& s = fmm_.scells_[sources[k]];
      const double rho = (r_target + s.radius) / norm(cell.center - s.mc);
      order_of[k] = m2l_order_ == M2lOrder::full ? p : m2l_order_for(rho, theta, p);
      ++first[order_of[k] + 1];
    }
    for (int q = 0; q <= p; ++q) first[q + 1] += first[q];
    std::vector<const double*> moments(sources.size());
    std::vector<Vec3> offsets(sources.size());
    std::vector<int> next(first.begin(), first.end() - 1);
    for (size_t k = 0; k < sources.size(); ++k) {
      const int at = next[order_of[k]]++;
      moments[at] = &M_[static_cast<size_t>(sources[k]) * ncoef_];
      offsets[at] = cell.center - fmm_.scells_[sources[k]].mc;
    }
    for (int q = 0; q <= p; ++q) {
      const int count = first[q + 1] - first[q];
      if (count == 0) continue;
      m2l_by_order_[q]->apply_float(moments.data() + first[q], offsets.data() + first[q], count, L);
      terms += count * m2l_by_order_[q]->terms();
    }
    ops += sources.size();
    if (cell.child_first < 0) build_near_plan(c);
  }
  // Then the parents' expansions down (parents first: by level, one pass per
  // level) and the field polynomials.
  for (size_t s = 0; s < todo.size();) {
    size_t e = s;
    const int level = fmm_.tcells_[todo[s]].level;
    while (e < todo.size() && fmm_.tcells_[todo[e]].level == level) ++e;
#pragma omp parallel for num_threads(threads_) schedule(static) if (e - s >= 32)
    for (long i = static_cast<long>(s); i < static_cast<long>(e); ++i) {
      const int c = todo[i];
      const auto& cell = fmm_.tcells_[c];
      double* L = local(slot_[c]);
      if (cell.parent >= 0) fmm_.basis_.l2l(local(slot_[cell.parent]), cell.center - fmm_.tcells_[cell.parent].center, L);
      field_expansion_->from_local(L, polynomials(slot_[c]));
    }
    s = e;
  }
  expansions_ += todo.size();
  m2l_ops_ += ops;
  m2l_terms_ += terms;
}

void TracerField::build_near_plan(int leaf) {
  NearPlan& plan = plans_[leaf];
  plan.runs.clear();
  plan.masks.clear();
  std::vector<Span> listed;
  for (int B : fmm_.near_[leaf]) listed.push_back(spans_[span_of_cell_[B]]);
  std::sort(listed.begin(), listed.end(), [](const Span& a, const Span& b) {
    return a.block != b.block ? a.block < b.block : a.first_slot < b.first_slot;
  });
  constexpr int L = tracer::kLanes;
  for (const Span& s : listed) {
    const int g_first = s.first_slot / L, g_last = (s.first_slot + s.count - 1) / L;
    // A new run where the block changes or a whole group is left out.
    if (plan.runs.empty() || plan.runs.back().block != s.block ||
        g_first > plan.runs.back().g0 + plan.runs.back().groups)
      plan.runs.push_back({s.block, g_first, 0, static_cast<int>(plan.masks.size())});
    NearRun& run = plan.runs.back();
    while (run.g0 + run.groups <= g_last) {
      plan.masks.push_back(0);
      ++run.groups;
    }
    for (int slot = s.first_slot; slot < s.first_slot + s.count; ++slot)
      plan.masks[run.mask0 + slot / L - run.g0] |= static_cast<uint8_t>(1u << (slot % L));
  }
}

void TracerField::field_outside(Vec3 x, Vec3* E, double* nearest) const {
  const SourceGeometry& src = fmm_.src_;
  const auto& root = fmm_.scells_[0];
  if (nearest) *nearest = std::numeric_limits<double>::infinity();
  if (root.radius < fmm_.opt_.theta * norm(x - root.mc)) {
    fmm_.basis_.m2p(&M_[0], x - root.mc, nullptr, E);
    return;
  }
  Vec3 e{0, 0, 0};
  for (size_t k = 0; k < fmm_.order_.size(); ++k) {
    const uint32_t j = fmm_.order_[k];
    Vec3 ej{0, 0, 0};
    unit_potential_field(src, j, x, nullptr, &ej);
    e += tri_charge_[k] * ej;
    if (nearest && src.area[j] > 0 && src.is_near(j, x))
      *nearest = std::min(*nearest, geometry::point_triangle_distance(x, src.a[j], src.b[j], src.c[j]));
  }
  *E += e;
}

int TracerField::locate(Vec3 x, int hint) const {
  if (hint >= 0) {
    const auto& c = fmm_.tcells_[hint];
    const Vec3 d = x - c.center;
    // Same tie rule as the descent (octant: strictly greater goes up) is not
    // needed here: any leaf whose closed box holds x gives a valid expansion.
    if (c.child_first < 0 && std::fabs(d.x) <= c.half && std::fabs(d.y) <= c.half && std::fabs(d.z) <= c.half)
      return hint;
  }
  return fmm_.locate(x);
}

void TracerField::field(int leaf, const Vec3* x, int count, Vec3* E, double* nearest) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (leaf < 0) {
    // Outside the target tree (callers size the region so this is rare).
    for (int i = 0; i < count; ++i) field_outside(x[i], &E[i], nearest ? &nearest[i] : nullptr);
    return;
  }
  const auto& cell = fmm_.tcells_[leaf];
  const NearPlan& plan = plans_[leaf];
  const double* G = polynomials(slot_[leaf]);
  for (int i = 0; i < count; ++i) {
    field_expansion_->evaluate(G, x[i] - cell.center, &E[i]);
    if (nearest) nearest[i] = inf;
  }
  const int m = m_;
  // Near-candidate bits of up to kGroups groups at a time (a leaf at the
  // tree's depth limit may hold more than leaf_size triangles).
  constexpr int kGroups = 16;
  uint8_t bits[kGroups];
  const int gf = tracer::group_floats(m);
  // Block run by block run, every point in turn: a run's floats (a few KB)
  // stay in L1 for all points of the chunk, where point by point the whole
  // near list (tens of KB) streamed from L2 per point.
  // Each point collects its near candidates and keeps its own batch of
  // float-rule triangles.
  constexpr int kPoints = 32;
  // Per-thread scratch, addressed once here: the library is built
  // position-independent, where every thread_local access is a call.
  thread_local std::vector<RuleBatch> batches_tls(kPoints);
  thread_local std::vector<std::vector<int>> candidates_tls(kPoints);
  thread_local std::vector<std::pair<int, double>> near_tls;
  std::vector<RuleBatch>& batches = batches_tls;
  std::vector<std::vector<int>>& candidates = candidates_tls;
  std::vector<std::pair<int, double>>& near_scratch = near_tls;
  double e[kPoints][3];
  for (int i0 = 0; i0 < count; i0 += kPoints) {
    const int np = std::min(kPoints, count - i0);
    for (int i = 0; i < np; ++i) {
      e[i][0] = e[i][1] = e[i][2] = 0;
      candidates[i].clear();
    }
    for (const NearRun& run : plan.runs) {
      const Block& blk = block_list_[run.block];
      for (int i = 0; i < np; ++i) {
        float xf[3];
        to_float(x[i0 + i] - blk.mc, xf);
        for (int g0 = 0; g0 < run.groups; g0 += kGroups) {
          const int ng = std::min(kGroups, run.groups - g0);
          const size_t g = static_cast<size_t>(run.g0 + g0);
          tracer::span_field(&blocks_[blk.block + g * gf], ng, m, xf, e[i], bits, &plan.masks[run.mask0 + g0]);
          for (int j = 0; j < ng; ++j)
            for (unsigned b = bits[j]; b != 0; b &= b - 1)
              candidates[i].push_back(slot_tri_[blk.slot0 + (g + j) * tracer::kLanes + __builtin_ctz(b)]);
        }
      }
    }
    for (int i = 0; i < np; ++i) {
      near_candidates(candidates[i].data(), static_cast<int>(candidates[i].size()), x[i0 + i], e[i],
                      nearest ? &nearest[i0 + i] : nullptr, batches[i], near_scratch);
      batches[i].flush(e[i]);
      E[i0 + i] += Vec3{e[i][0], e[i][1], e[i][2]};
    }
  }
}

void TracerField::near_candidates(const int* ks, int n, Vec3 x, double* e, double* nearest, RuleBatch& batch,
                                  std::vector<std::pair<int, double>>& near) const {
  near.clear();
  double closest_centroid2 = std::numeric_limits<double>::infinity();
  int closest = -1;
  for (int c = 0; c < n; ++c) {
    const int k = ks[c];
    const NearTest& t = near_test_[k];
    const double q = tri_charge_[k];
    const double d2 = norm2(x - t.centroid);
    if (!(d2 < t.near2)) {
      // A float candidate the double test rejects: its own quadrature points.
      const size_t p0 = static_cast<size_t>(k) * m_;
      const Vec3 ej = scalar_sum(&fmm_.points_[p0], &pq_[p0], m_, x);
      e[0] += ej.x;
      e[1] += ej.y;
      e[2] += ej.z;
      continue;
    }
    if (!t.has_area) continue;
    const NearTriangle& tri = near_tris_[k];
    if (!(d2 < t.split2)) {
      batch.add(!(d2 < t.whole2), x, tri.frame, q, e);
    } else {
      batch.closed.add(tri.frame, q / tri.area, x, e);
    }
    if (!nearest) continue;
    near.push_back({k, d2});
    if (d2 < closest_centroid2) {
      closest_centroid2 = d2;
      closest = static_cast<int>(near.size()) - 1;
    }
  }
  if (!nearest) return;
  double best = std::numeric_limits<double>::infinity();
  if (closest < 0) {
    *nearest = best;
    return;
  }
  // The centroid lies in its triangle, so the triangle with the nearest
  // centroid bounds the distance from above; every point of a triangle lies
  // within radius of its centroid, so |x - centroid| - radius bounds its
  // distance from below: most near triangles cannot beat the bound.
  auto distance = [&](int k) {
    const tracer::TriangleFrame& f = near_tris_[k].frame;
    return geometry::point_triangle_distance(x, f.v[0], f.v[1], f.v[2]);
  };
  best = distance(near[closest].first);
  for (size_t c = 0; c < near.size(); ++c) {
    if (static_cast<int>(c) == closest) continue;
    const auto [k, d2] = near[c];
    if (std::sqrt(d2) - near_test_[k].radius < best) best = std::min(best, distance(k));
  }
  *nearest = best;
}

size_t TracerField::memory_bytes() const {
  return (pq_.size() + tri_charge_.size() + M_.size() + pages_.size() * kPageSlots * slot_doubles_) * sizeof(double) +
         near_tris_.size() * (sizeof(NearTriangle) + sizeof(NearTest)) +
         blocks_.size() * sizeof(float) + (span_of_cell_.size() + slot_.size() + slot_tri_.size()) * sizeof(int) +
         spans_.size() * sizeof(Span) + block_list_.size() * sizeof(Block) + plans_.size() * sizeof(NearPlan);
}

}  // namespace soupuv::field
