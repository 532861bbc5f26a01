// Dual-tree FMM over charged triangles (see fmm.h for the picture).
#include "soupuv/field/fmm.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "soupuv/field/triangle_integrals.h"
#include "soupuv/geometry/closest_point.h"
#include "tracer_m2l.h"

namespace soupuv::field {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
constexpr int kMaxLevel = 24;
constexpr double kSqrt3 = 1.7320508075688772;

int octant(Vec3 p, Vec3 c) { return (p.x > c.x) | ((p.y > c.y) << 1) | ((p.z > c.z) << 2); }
Vec3 child_center(Vec3 c, double half, int o) {
  double q = half / 2;
  return {c.x + ((o & 1) ? q : -q), c.y + ((o & 2) ? q : -q), c.z + ((o & 4) ? q : -q)};
}
int threads_or_default(int t) { return t > 0 ? t : omp_get_max_threads(); }
}  // namespace

Fmm::Fmm(const SourceGeometry& sources, const FmmOptions& options, Box3 region)
    : src_(sources), opt_(options), basis_(options.order), ncoef_(basis_.size()) {
  auto t0 = Clock::now();
  build_source_tree();
  build_target_tree(region, nullptr);
  stats_.build_seconds = since(t0);
}

Fmm::Fmm(const SourceGeometry& sources, const FmmOptions& options, const std::vector<Vec3>& targets)
    : src_(sources), opt_(options), basis_(options.order), ncoef_(basis_.size()) {
  auto t0 = Clock::now();
  build_source_tree();
  Box3 region;
  for (Vec3 x : targets) region.add(x);
  build_target_tree(region, &targets);
  stats_.build_seconds = since(t0);
}

Fmm::Fmm(const Fmm& other, int order)
    : src_(other.src_), opt_(other.opt_), basis_(order), ncoef_(basis_.size()), order_(other.order_),
      scells_(other.scells_), slevels_(other.slevels_), point_charge_(other.point_charge_.size(), 0.0),
      points_(other.points_), tri_charge_(other.tri_charge_.size(), 0.0), tcells_(other.tcells_),
      tlevels_(other.tlevels_), m2l_(other.m2l_), near_(other.near_), stats_(other.stats_) {
  opt_.order = order;
  stats_.build_seconds = 0;
}

void Fmm::build_source_tree() {
  const size_t n = src_.size();
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) order_[i] = static_cast<uint32_t>(i);
  Box3 box, vertices;
  for (size_t i = 0; i < n; ++i) {
    box.add(src_.centroid[i]);
    vertices.add(src_.a[i]), vertices.add(src_.b[i]), vertices.add(src_.c[i]);
  }
  if (box.empty()) box.add({0, 0, 0});
  Vec3 ext = box.extent();
  // Centroids that (nearly) coincide, as for a single triangle, would give a
  // root of no size, and target cells would split toward it without end
  // (out of memory on a one-triangle soup): then the triangles' own box.
  const Vec3 vext = vertices.empty() ? Vec3{0, 0, 0} : vertices.extent();
  if (std::max({ext.x, ext.y, ext.z}) < 1e-3 * std::max({vext.x, vext.y, vext.z})) {
    box = vertices;
    ext = vext;
  }
  double half = 0.5 * std::max({ext.x, ext.y, ext.z, 1e-12}) * 1.0001;
  scells_.push_back({box.center(), half, {}, 0, 0, static_cast<int>(n), -1, 0, 0});
  // Breadth-first: children of a cell are created contiguously.
  for (size_t ci = 0; ci < scells_.size(); ++ci) {
    SourceCell cell = scells_[ci];
    if (cell.count <= opt_.leaf_size || cell.level >= kMaxLevel) continue;
    std::array<std::vector<uint32_t>, 8> parts;
    for (int k = cell.first; k < cell.first + cell.count; ++k)
      parts[octant(src_.centroid[order_[k]], cell.center)].push_back(order_[k]);
    int pos = cell.first;
    scells_[ci].child_first = static_cast<int>(scells_.size());
    for (int o = 0; o < 8; ++o) {
      if (parts[o].empty()) continue;
      SourceCell ch;
      ch.center = child_center(cell.center, cell.half, o);
      ch.half = cell.half / 2;
      ch.first = pos;
      ch.count = static_cast<int>(parts[o].size());
      ch.level = cell.level + 1;
      std::copy(parts[o].begin(), parts[o].end(), order_.begin() + pos);
      pos += ch.count;
      scells_.push_back(ch);
      ++scells_[ci].children;
    }
  }
  // Expansion centres and radii enclose every vertex of the cell's triangles,
  // so both the quadrature points and the closed-form supports are covered.
  for (auto& cell : scells_) {
    Box3 b;
    for (int k = cell.first; k < cell.first + cell.count; ++k) {
      uint32_t j = order_[k];
      b.add(src_.a[j]); b.add(src_.b[j]); b.add(src_.c[j]);
    }
    if (b.empty()) b.add(cell.center);
    cell.mc = b.center();
    double r2 = 0;
    for (int k = cell.first; k < cell.first + cell.count; ++k) {
      uint32_t j = order_[k];
      r2 = std::max({r2, norm2(src_.a[j] - cell.mc), norm2(src_.b[j] - cell.mc), norm2(src_.c[j] - cell.mc)});
    }
    cell.radius = std::sqrt(r2);
    if (static_cast<int>(slevels_.size()) <= cell.level) slevels_.resize(cell.level + 1);
  }
  for (size_t ci = 0; ci < scells_.size(); ++ci) {
    slevels_[scells_[ci].level].push_back(static_cast<int>(ci));
    ++stats_.source_cells;
    if (scells_[ci].children == 0) ++stats_.source_leaves;
  }
  const int m = src_.points_per_triangle;
  points_.resize(n * m);
  for (size_t k = 0; k < n; ++k)
    for (int q = 0; q < m; ++q) points_[k * m + q] = src_.qpoints[order_[k] * m + q];
  point_charge_.assign(n * m, 0.0);
  tri_charge_.assign(n, 0.0);
}

// One target subtree under construction: the dual-tree traversal below a
// target cell. The whole tree is one such build (from the root), whose calls
// below `defer_half` are not run but queued per frontier cell; each frontier
// cell's subtree is then built by its own TargetBuild, in parallel, and
// spliced into the tree. Cells are numbered locally (0: the subtree's root).
// A subtree sees its pairs in the serial traversal's order, so every cell's
// M2L and near lists come out the same as serially (only cell numbers differ).
struct Fmm::TargetBuild {
  const Fmm& fmm;
  double defer_half;  // 0: defer nothing
  std::vector<TargetCell> cells;
  std::vector<std::vector<int>> m2l, near;
  std::vector<std::vector<uint32_t>> members;  // per cell, known targets (while building)
  std::vector<std::vector<int>> deferred;      // per cell, source cells queued for its own build
  std::vector<int> frontier;                   // cells with queued pairs, in order of their first
  size_t m2l_pairs = 0, near_pairs = 0;

  TargetBuild(const Fmm& f, TargetCell root, double defer) : fmm(f), defer_half(defer) { add_cell(root); }

  void add_cell(const TargetCell& c) {
    cells.push_back(c);
    m2l.emplace_back();
    near.emplace_back();
    if (c.targets >= 0) members.resize(cells.size());
    if (defer_half > 0) deferred.resize(cells.size());
  }
  bool deferred_cell(int A) const { return defer_half > 0 && A > 0 && cells[A].half <= defer_half; }

  void split(int A) {
    if (cells[A].child_first >= 0) return;
    const TargetCell parent = cells[A];
    cells[A].child_first = static_cast<int>(cells.size());
    for (int o = 0; o < 8; ++o) {
      TargetCell ch;
      ch.center = child_center(parent.center, parent.half, o);
      ch.half = parent.half / 2;
      ch.parent = A;
      ch.level = parent.level + 1;
      if (parent.targets >= 0) ch.targets = 0;
      add_cell(ch);
    }
    if (parent.targets >= 0) {
      std::vector<uint32_t> list = std::move(members[A]);
      members[A].clear();
      const int first = cells[A].child_first;
      for (uint32_t i : list) {
        const int c = first + octant(fmm.target_points_[i], parent.center);
        members[c].push_back(i);
        ++cells[c].targets;
      }
    }
  }

  void traverse(int A, int B) {
    if (deferred_cell(A)) {
      if (deferred[A].empty()) frontier.push_back(A);
      deferred[A].push_back(B);
      return;
    }
    const SourceCell& sb = fmm.scells_[B];
    const double rA = cells[A].half * kSqrt3;
    const double d = norm(cells[A].center - sb.mc);
    if (rA + sb.radius < fmm.opt_.theta * d) {
      m2l[A].push_back(B);
      ++m2l_pairs;
      return;
    }
    if (cells[A].targets == 0) return;  // no target will ever ask here
    const bool b_leaf = sb.children == 0;
    const bool a_small = cells[A].half <= sb.half * fmm.opt_.target_coarsening * 1.0001 ||
                         cells[A].level >= kMaxLevel ||
                         (cells[A].targets >= 0 && cells[A].targets <= fmm.opt_.leaf_size);
    if (b_leaf && a_small && cells[A].child_first < 0) {
      near[A].push_back(B);
      ++near_pairs;
      return;
    }
    if (!b_leaf && (a_small || sb.half >= cells[A].half)) {
      const int first = sb.child_first, count = sb.children;
      for (int k = 0; k < count; ++k) traverse(A, first + k);
      return;
    }
    split(A);
    const int first = cells[A].child_first;
    for (int o = 0; o < 8; ++o) traverse(first + o, B);
  }

  // A cell that was a leaf when it met a source leaf may have been split by a
  // later pair: hand its direct pairs down to its children (which may split
  // further; children always come after their parent, so one pass suffices).
  // Deferred cells hand theirs down in their own build.
  void hand_down() {
    for (size_t A = 0; A < cells.size(); ++A) {
      if (cells[A].child_first < 0 || near[A].empty() || deferred_cell(static_cast<int>(A))) continue;
      std::vector<int> list = std::move(near[A]);
      near[A].clear();
      near_pairs -= list.size();
      for (int B : list)
        for (int o = 0; o < 8; ++o) traverse(cells[A].child_first + o, B);
    }
  }
};

void Fmm::build_target_tree(Box3 region, const std::vector<Vec3>* targets) {
  Box3 box = region;
  for (size_t i = 0; i < src_.size(); ++i) {
    box.add(src_.a[i]); box.add(src_.b[i]); box.add(src_.c[i]);
  }
  if (box.empty()) box.add({0, 0, 0});
  Vec3 ext = box.extent();
  double half = 0.5 * std::max({ext.x, ext.y, ext.z, 1e-12}) * 1.001;
  TargetCell root{-1, box.center(), half, -1, -1, 0};
  if (targets) {
    target_points_ = *targets;
    root.targets = static_cast<int>(targets->size());
  }
  // The traversal was ~0.6 s of serial set-up at 204,800 triangles. Subtrees
  // of target cells of an eighth of the source root's size (up to ~512 over
  // the sources) are built in parallel.
  const int nth = threads_or_default(opt_.threads);
  const bool parallel = nth > 1 && src_.size() >= 4096;
  TargetBuild top(*this, root, parallel && !scells_.empty() ? scells_[0].half / 8 : 0.0);
  if (targets) {
    top.members[0].resize(targets->size());
    for (size_t i = 0; i < targets->size(); ++i) top.members[0][i] = static_cast<uint32_t>(i);
  }
  if (!scells_.empty() && src_.size() > 0) top.traverse(0, 0);
  top.hand_down();

  // Each frontier cell's subtree on its own; cell 0 of a subtree is the
  // frontier cell itself.
  const long nf = static_cast<long>(top.frontier.size());
  std::vector<std::unique_ptr<TargetBuild>> sub(nf);
#pragma omp parallel for num_threads(nth) schedule(dynamic, 1) if (nf > 1)
  for (long f = 0; f < nf; ++f) {
    const int A = top.frontier[f];
    TargetCell c = top.cells[A];
    c.parent = -1;
    sub[f] = std::make_unique<TargetBuild>(*this, c, 0.0);
    TargetBuild& b = *sub[f];
    if (c.targets >= 0) b.members[0] = std::move(top.members[A]);
    for (int B : top.deferred[A]) b.traverse(0, B);
    b.hand_down();
  }

  // Splice: subtree cells 1.. follow the top build's cells, subtree by subtree.
  std::vector<size_t> base(nf + 1, top.cells.size());
  for (long f = 0; f < nf; ++f) base[f + 1] = base[f] + sub[f]->cells.size() - 1;
  tcells_ = std::move(top.cells);
  m2l_ = std::move(top.m2l);
  near_ = std::move(top.near);
  tcells_.resize(base[nf]);
  m2l_.resize(base[nf]);
  near_.resize(base[nf]);
  stats_.m2l_pairs = top.m2l_pairs;
  stats_.near_leaf_pairs = top.near_pairs;
  for (long f = 0; f < nf; ++f) {
    stats_.m2l_pairs += sub[f]->m2l_pairs;
    stats_.near_leaf_pairs += sub[f]->near_pairs;
  }
#pragma omp parallel for num_threads(nth) schedule(dynamic, 1) if (nf > 1)
  for (long f = 0; f < nf; ++f) {
    TargetBuild& b = *sub[f];
    const int A = top.frontier[f];
    auto global = [&](int local) { return local == 0 ? A : static_cast<int>(base[f] + local - 1); };
    for (size_t k = 0; k < b.cells.size(); ++k) {
      TargetCell c = b.cells[k];
      const int g = global(static_cast<int>(k));
      c.parent = k == 0 ? tcells_[A].parent : global(c.parent);
      if (c.child_first >= 0) c.child_first = global(c.child_first);
      tcells_[g] = c;
      m2l_[g] = std::move(b.m2l[k]);
      near_[g] = std::move(b.near[k]);
    }
    sub[f].reset();
  }
  for (size_t A = 0; A < tcells_.size(); ++A) {
    if (static_cast<int>(tlevels_.size()) <= tcells_[A].level) tlevels_.resize(tcells_[A].level + 1);
    tlevels_[tcells_[A].level].push_back(static_cast<int>(A));
  }
  stats_.target_cells = tcells_.size();
}

void Fmm::set_charges(const std::vector<double>& charges) {
  const int nth = threads_or_default(opt_.threads);
  const int m = src_.points_per_triangle;
  const long n = static_cast<long>(src_.size());
  auto t0 = Clock::now();
#pragma omp parallel for num_threads(nth) schedule(static)
  for (long k = 0; k < n; ++k) {
    double q = charges[order_[k]];
    tri_charge_[k] = q;
    for (int i = 0; i < m; ++i) point_charge_[k * m + i] = q * src_.qweights[i];
  }
  M_.assign(scells_.size() * ncoef_, 0.0);
  for (int level = static_cast<int>(slevels_.size()) - 1; level >= 0; --level) {
    const auto& cells = slevels_[level];
    // A fork/join per level: not worth it for the few cells near the root
    // (on a loaded machine each join waits for a descheduled thread).
#pragma omp parallel for num_threads(nth) schedule(dynamic, 4) if (cells.size() >= 16)
    for (long i = 0; i < static_cast<long>(cells.size()); ++i) {
      const SourceCell& c = scells_[cells[i]];
      double* M = &M_[static_cast<size_t>(cells[i]) * ncoef_];
      if (c.children == 0) {
        basis_.p2m(c.mc, &points_[static_cast<size_t>(c.first) * m], &point_charge_[static_cast<size_t>(c.first) * m],
                   c.count * m, M);
      } else {
        for (int k = 0; k < c.children; ++k) {
          const SourceCell& ch = scells_[c.child_first + k];
          basis_.m2m(&M_[static_cast<size_t>(c.child_first + k) * ncoef_], ch.mc - c.mc, M);
        }
      }
    }
  }
  stats_.upward_seconds = since(t0);
  t0 = Clock::now();
  L_.assign(tcells_.size() * ncoef_, 0.0);
  // All M2Ls of a target cell in one batched call, four sources side by
  // side in SIMD lanes (tracer_m2l.h; the same operator as TaylorBasis::m2l):
  // the M2L was ~45 % of a charge solve one pair at a time.
  const tracer::BatchM2L batch(basis_);
#pragma omp parallel num_threads(nth)
  {
    std::vector<const double*> moments;
    std::vector<Vec3> offsets;
#pragma omp for schedule(dynamic, 8)
    for (long A = 0; A < static_cast<long>(tcells_.size()); ++A) {
      const auto& list = m2l_[A];
      if (list.empty()) continue;
      moments.resize(list.size());
      offsets.resize(list.size());
      for (size_t k = 0; k < list.size(); ++k) {
        moments[k] = &M_[static_cast<size_t>(list[k]) * ncoef_];
        offsets[k] = tcells_[A].center - scells_[list[k]].mc;
      }
      batch.apply(moments.data(), offsets.data(), static_cast<int>(list.size()),
                  &L_[static_cast<size_t>(A) * ncoef_]);
    }
  }
  stats_.m2l_seconds = since(t0);
  t0 = Clock::now();
  for (size_t level = 1; level < tlevels_.size(); ++level) {
    const auto& cells = tlevels_[level];
#pragma omp parallel for num_threads(nth) schedule(static) if (cells.size() >= 256)
    for (long i = 0; i < static_cast<long>(cells.size()); ++i) {
      const TargetCell& c = tcells_[cells[i]];
      basis_.l2l(&L_[static_cast<size_t>(c.parent) * ncoef_], c.center - tcells_[c.parent].center,
                 &L_[static_cast<size_t>(cells[i]) * ncoef_]);
    }
  }
  stats_.downward_seconds = since(t0);
}

int Fmm::locate(Vec3 x) const {
  const TargetCell& root = tcells_[0];
  Vec3 d = x - root.center;
  if (std::fabs(d.x) > root.half || std::fabs(d.y) > root.half || std::fabs(d.z) > root.half) return -1;
  int A = 0;
  while (tcells_[A].child_first >= 0) A = tcells_[A].child_first + octant(x, tcells_[A].center);
  return A;
}

double Fmm::near_part(int leaf, Vec3 x, double* phi, Vec3* E, bool skip_close, bool want_nearest) const {
  const int m = src_.points_per_triangle;
  double nearest = std::numeric_limits<double>::infinity();
  double f = 0;
  double ex = 0, ey = 0, ez = 0;
  for (int B : near_[leaf]) {
    const SourceCell& c = scells_[B];
    for (int k = c.first; k < c.first + c.count; ++k) {
      const uint32_t j = order_[k];
      const double q = tri_charge_[k];
      if (src_.is_near(j, x)) {
        if (skip_close) continue;
        if (!(src_.area[j] > 0)) continue;
        double pj = 0;
        Vec3 ej{0, 0, 0};
        near_potential_field(src_, j, x, phi ? &pj : nullptr, E ? &ej : nullptr);
        f += q * pj;
        ex += q * ej.x; ey += q * ej.y; ez += q * ej.z;
        if (want_nearest) nearest = std::min(nearest, geometry::point_triangle_distance(x, src_.a[j], src_.b[j], src_.c[j]));
        continue;
      }
      const Vec3* p = &points_[static_cast<size_t>(k) * m];
      const double* w = &point_charge_[static_cast<size_t>(k) * m];
      for (int i = 0; i < m; ++i) {
        double dx = x.x - p[i].x, dy = x.y - p[i].y, dz = x.z - p[i].z;
        double inv = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
        double wi = w[i] * inv;
        f += wi;
        double w3 = wi * inv * inv;
        ex += w3 * dx; ey += w3 * dy; ez += w3 * dz;
      }
    }
  }
  if (phi) *phi += f;
  if (E) *E += Vec3{ex, ey, ez};
  return nearest;
}

void Fmm::evaluate(Vec3 x, double* phi, Vec3* E, double* nearest_close) const {
  int leaf = locate(x);
  if (leaf < 0) {
    // Outside the target region: the source root's multipole when it is well
    // separated, else every source leaf directly (rare; callers size the region).
    const SourceCell& root = scells_[0];
    if (root.radius < opt_.theta * norm(x - root.mc)) {
      basis_.m2p(&M_[0], x - root.mc, phi, E);
      if (nearest_close) *nearest_close = std::numeric_limits<double>::infinity();
      return;
    }
    double f = 0;
    Vec3 e{0, 0, 0};
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < order_.size(); ++k) {
      uint32_t j = order_[k];
      double pj = 0;
      Vec3 ej{0, 0, 0};
      unit_potential_field(src_, j, x, &pj, &ej);
      f += tri_charge_[k] * pj;
      e += tri_charge_[k] * ej;
      if (src_.is_near(j, x))
        nearest = std::min(nearest, geometry::point_triangle_distance(x, src_.a[j], src_.b[j], src_.c[j]));
    }
    if (phi) *phi += f;
    if (E) *E += e;
    if (nearest_close) *nearest_close = nearest;
    return;
  }
  basis_.l2p(&L_[static_cast<size_t>(leaf) * ncoef_], x - tcells_[leaf].center, phi, E);
  double nearest = near_part(leaf, x, phi, E, false, nearest_close != nullptr);
  if (nearest_close) *nearest_close = nearest;
}

double Fmm::potential_without_close(int leaf, Vec3 x) const {
  double phi = 0;
  basis_.l2p(&L_[static_cast<size_t>(leaf) * ncoef_], x - tcells_[leaf].center, &phi, nullptr);
  near_part(leaf, x, &phi, nullptr, true, false);
  return phi;
}

double Fmm::far_potential(int leaf, Vec3 x) const {
  double phi = 0;
  basis_.l2p(&L_[static_cast<size_t>(leaf) * ncoef_], x - tcells_[leaf].center, &phi, nullptr);
  return phi;
}

std::vector<uint32_t> Fmm::near_source_triangles(int leaf) const {
  std::vector<uint32_t> out;
  for (int B : near_[leaf]) {
    const SourceCell& c = scells_[B];
    out.insert(out.end(), order_.begin() + c.first, order_.begin() + c.first + c.count);
  }
  return out;
}

std::vector<std::vector<uint32_t>> Fmm::source_leaf_triangles() const {
  std::vector<std::vector<uint32_t>> out;
  for (const auto& c : scells_)
    if (c.children == 0) out.emplace_back(order_.begin() + c.first, order_.begin() + c.first + c.count);
  return out;
}

std::vector<std::vector<uint32_t>> Fmm::source_blocks(int max_count) const {
  std::vector<std::vector<uint32_t>> out;
  if (scells_.empty()) return out;
  // A cell too large to be a block splits into its children; runs of
  // neighbouring (consecutive octant) children that fit together form one
  // block. Taking each child alone left most blocks at a fraction of
  // max_count (a cell of 200 gives 8 blocks of ~25), and a block-Jacobi
  // preconditioner is only as strong as its blocks are large.
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const SourceCell& c = scells_[stack.back()];
    stack.pop_back();
    if (c.count <= max_count || c.children == 0) {
      out.emplace_back(order_.begin() + c.first, order_.begin() + c.first + c.count);
      continue;
    }
    int run_first = -1, run_count = 0;  // a run of children in order_ (contiguous)
    auto flush = [&] {
      if (run_count > 0) out.emplace_back(order_.begin() + run_first, order_.begin() + run_first + run_count);
      run_first = -1;
      run_count = 0;
    };
    for (int k = 0; k < c.children; ++k) {
      const SourceCell& ch = scells_[c.child_first + k];
      if (ch.count > max_count && ch.children > 0) {
        flush();
        stack.push_back(c.child_first + k);
        continue;
      }
      if (run_count + ch.count > max_count) flush();
      if (run_count == 0) run_first = ch.first;
      run_count += ch.count;
    }
    flush();
  }
  return out;
}

}  // namespace soupuv::field
