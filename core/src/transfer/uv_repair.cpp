#include "soupuv/transfer/uv_repair.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "soupuv/errors.h"
#include "soupuv/union_find.h"
#include "transfer/sym_dirichlet.h"
#include "transfer/untangle_energy.h"
#include "transfer/uv_vertices.h"

namespace soupuv::transfer {

nlohmann::json UvRepairResult::diagnostics() const {
  return {{"bad_triangles", bad_triangles},
          {"bad_triangles_after", bad_triangles_after},
          {"patches", patches},
          {"repaired_patches", repaired_patches},
          {"failed_patches", failed_patches},
          {"failed_no_start", failed_no_start},
          {"failed_no_gain", failed_no_gain},
          {"failed_sliver", failed_sliver},
          {"failed_too_large", failed_too_large},
          {"repaired_vertices", repaired_vertices},
          {"repaired_triangles", repaired_triangles},
          {"failed_detail", failed_detail},
          {"slowest_patches", slowest_patches},
          {"seconds", seconds}};
}

namespace {

using detail::RestTriangle;
using detail::UvVertices;
using detail::uv_vertices;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kFixed = UINT32_MAX;
constexpr double kMinAreaRatio = 1e-3;

double signed_area2(const std::array<Vec2, 3>& uv) { return cross(uv[1] - uv[0], uv[2] - uv[0]); }

bool in_unit_square(Vec2 p) { return p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1; }

// A triangle's L2 stretch (Sander et al., UV onto surface, at the global
// scale) and its largest expansion (singular value of surface -> UV); false
// when flipped or collapsed.
bool stretch_of(const RestTriangle& r, const std::array<Vec2, 3>& uv, double& stretch,
                double& expansion) {
  const detail::Jacobian J = detail::jacobian(r, uv);
  const double d = J.det();
  if (!(d > 0)) return false;
  // Sander's L2 stretch of the inverse map is sqrt((1/s1^2 + 1/s2^2) / 2).
  const double f = J.frobenius2();
  const double root = std::sqrt(std::max(0.0, f * f - 4 * d * d));
  const double s1sq = 0.5 * (f + root), s2sq = std::max(0.5 * (f - root), d * d / s1sq);
  stretch = std::sqrt(0.5 * (1 / s1sq + 1 / s2sq));
  expansion = std::sqrt(s1sq);
  return true;
}

// The area-weighted median stretch over unflipped triangles (1 if none).
double median_stretch(const std::vector<RestTriangle>& rest,
                      const std::vector<std::array<Vec2, 3>>& uvs) {
  struct Weighted { double value, area; };
  std::vector<Weighted> finite;
  for (size_t t = 0; t < rest.size(); ++t) {
    double s, e;
    if (rest[t].valid && stretch_of(rest[t], uvs[t], s, e)) finite.push_back({s, rest[t].area});
  }
  if (finite.empty()) return 1;
  std::sort(finite.begin(), finite.end(), [](auto& a, auto& b) { return a.value < b.value; });
  double total = 0, below = 0;
  for (auto& w : finite) total += w.area;
  for (auto& w : finite) {
    below += w.area;
    if (below >= 0.5 * total) return w.value;
  }
  return finite.back().value;
}

// Whether one triangle needs repair (see UvRepairOptions), given the median.
bool is_bad(const RestTriangle& r, const std::array<Vec2, 3>& uv, double median,
            const UvRepairOptions& o) {
  if (!r.valid) return false;
  double stretch, expansion;
  if (!stretch_of(r, uv, stretch, expansion)) return true;  // flipped or collapsed
  return stretch > o.stretch_threshold * median || expansion > o.expansion_threshold;
}

// Which triangles need repair.
std::vector<uint8_t> find_bad(const std::vector<RestTriangle>& rest,
                              const std::vector<std::array<Vec2, 3>>& uvs,
                              const UvRepairOptions& o) {
  const double median = median_stretch(rest, uvs);
  std::vector<uint8_t> bad(rest.size(), 0);
  for (size_t t = 0; t < rest.size(); ++t) bad[t] = is_bad(rest[t], uvs[t], median, o);
  return bad;
}

// One patch: free UV vertices, the triangles around them, and their corners
// as either a free vertex (local index) or a fixed corner UV.
class Patch {
 public:
  Patch(const std::vector<uint32_t>& free_vertices, const UvVertices& verts,
        const std::vector<RestTriangle>& rest, const std::vector<std::array<Vec2, 3>>& uvs,
        const std::vector<uint8_t>& foreign)
      : free_(free_vertices), rest_(rest), uvs_(uvs), foreign_(foreign) {
    std::unordered_map<uint32_t, uint32_t> local;
    for (size_t i = 0; i < free_.size(); ++i) local[free_[i]] = uint32_t(i);
    std::vector<uint32_t> tris;
    for (uint32_t v : free_)
      for (uint32_t e = verts.start[v]; e < verts.start[v + 1]; ++e) tris.push_back(verts.corners[e] / 3);
    std::sort(tris.begin(), tris.end());
    tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
    triangles_ = tris;
    slot_.resize(tris.size());
    around_.resize(free_.size());
    for (size_t i = 0; i < tris.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        auto it = local.find(verts.of_corner[3 * tris[i] + k]);
        slot_[i][k] = it == local.end() ? kFixed : it->second;
        if (it != local.end()) around_[it->second].push_back({uint32_t(i), uint8_t(k)});
      }
    uv_.assign(free_.size(), Vec2{0, 0});
  }

  const std::vector<uint32_t>& triangles() const { return triangles_; }
  const std::vector<uint32_t>& free_vertices() const { return free_; }
  Vec2 uv(size_t i) const { return uv_[i]; }

  // The patch triangles' corner UVs with the free vertices at uv_.
  std::array<Vec2, 3> corners(size_t i) const {
    std::array<Vec2, 3> c = uvs_[triangles_[i]];
    for (int k = 0; k < 3; ++k)
      if (slot_[i][k] != kFixed) c[k] = uv_[slot_[i][k]];
    return c;
  }

  double energy_of(size_t i) const {
    return rest_[triangles_[i]].valid ? detail::energy(rest_[triangles_[i]], corners(i)) : 0.0;
  }
  double energy() const {
    double e = 0;
    for (size_t i = 0; i < triangles_.size(); ++i) e += energy_of(i);
    return e;
  }
  // Every triangle keeps at least kMinAreaRatio of its isometric UV area. The
  // barrier alone only keeps areas positive: a patch whose fixed ring is
  // itself collapsed (many lines converged on one point) can lower its
  // energy while staying a sliver of 1e-9, which is a fold in float UVs.
  // ... and every free vertex inside [0,1]^2 (a start may put it outside;
  // the line search never moves it out, but cannot always bring it back).
  bool unfolded() const {
    for (const Vec2& p : uv_)
      if (!in_unit_square(p)) return false;
    for (size_t i = 0; i < triangles_.size(); ++i) {
      const RestTriangle& r = rest_[triangles_[i]];
      if (r.valid && !(detail::jacobian(r, corners(i)).det() >= kMinAreaRatio)) return false;
    }
    return true;
  }

  // The energy before the repair (the corners' own UVs).
  double original_energy() const {
    double e = 0;
    for (uint32_t t : triangles_) e += rest_[t].valid ? detail::energy(rest_[t], uvs_[t]) : 0.0;
    return e;
  }

  // Start 1: each free vertex at the mean of its copies' UVs, leaving out
  // copies that landed on another chart than their triangle's (they lie
  // far away on that chart) unless every copy did.
  void start_at_copies() {
    for (size_t i = 0; i < free_.size(); ++i) {
      Vec2 sum{0, 0}, all{0, 0};
      double count = 0;
      for (auto [tri, k] : around_[i]) {
        const Vec2 p = uvs_[triangles_[tri]][k];
        all = all + p;
        if (foreign_.empty() || !foreign_[3 * triangles_[tri] + k]) { sum = sum + p; count += 1; }
      }
      uv_[i] = count > 0 ? (1.0 / count) * sum : (1.0 / double(around_[i].size())) * all;
    }
  }

  // Start 2: Tutte's embedding with uniform weights — each free vertex at
  // the mean of its neighbours, the fixed corners held at their own UVs —
  // solved by Gauss-Seidel. Flip-free when the fixed boundary is convex.
  void start_tutte(int iterations) {
    start_at_copies();
    for (int it = 0; it < iterations; ++it) {
      double moved = 0;
      for (size_t i = 0; i < free_.size(); ++i) {
        Vec2 sum{0, 0};
        double count = 0;
        for (auto [tri, k] : around_[i]) {
          const std::array<Vec2, 3> c = corners(tri);
          for (int j = 1; j <= 2; ++j) sum = sum + c[(k + j) % 3];
          count += 2;
        }
        const Vec2 next = (1.0 / count) * sum;
        moved = std::max(moved, norm(next - uv_[i]));
        uv_[i] = next;
      }
      if (moved < 1e-12) break;
    }
  }

  // Start 3, for patches Tutte folds (an open chart border, a concave
  // ring): unfold the triangles one by one from the fixed corners inwards,
  // each free vertex placed where the similarity that maps a triangle's rest
  // edge onto its two placed corners puts it (the mean over such triangles).
  void start_unfolding() {
    std::vector<uint8_t> placed(free_.size(), 0);
    unfold_from(placed);
  }

  bool has_fixed_corner() const {
    for (const auto& s : slot_)
      for (uint32_t k : s)
        if (k == kFixed) return true;
    return false;
  }

  // Start 0, for a chart island (no fixed corner: nothing anchors the
  // patch, e.g. triangles whose corners landed on two charts, or a part
  // the weld cut off): lay the first valid triangle down isometrically at
  // its own corner 0's UV (a point on this chart), then unfold the rest
  // from it. Descending from the copies' UVs instead had to shrink
  // triangles spanning two charts by 100x, which 100 sweeps do not do.
  void start_island() {
    start_at_copies();
    std::vector<uint8_t> placed(free_.size(), 0);
    // Triangles meeting the placed part at one vertex only (or not at all)
    // are not reached by unfolding: lay each down isometrically in turn,
    // hinged at its placed corner if it has one.
    for (size_t i = 0; i < triangles_.size(); ++i) {
      const RestTriangle& r = rest_[triangles_[i]];
      int hinge = -1, unplaced = 0;
      for (int k = 0; k < 3; ++k) {
        if (placed[slot_[i][k]]) hinge = k;
        else ++unplaced;
      }
      if (!r.valid || unplaced == 0 || unplaced == 1) continue;
      Vec2 at;
      if (hinge >= 0) {
        at = uv_[slot_[i][hinge]] - r.x[hinge];
      } else {
        // At the triangle's own corner 0's UV (a point on this chart),
        // kept inside [0,1]^2 when that sits at an edge.
        const Vec2 anchor = uvs_[triangles_[i]][0];
        Vec2 lo{0, 0}, hi{0, 0};
        for (int k = 0; k < 3; ++k) {
          lo = {std::min(lo.x, r.x[k].x), std::min(lo.y, r.x[k].y)};
          hi = {std::max(hi.x, r.x[k].x), std::max(hi.y, r.x[k].y)};
        }
        at = {std::clamp(anchor.x, -lo.x, 1 - hi.x), std::clamp(anchor.y, -lo.y, 1 - hi.y)};
      }
      for (int k = 0; k < 3; ++k)
        if (!placed[slot_[i][k]]) {
          uv_[slot_[i][k]] = at + r.x[k];
          placed[slot_[i][k]] = 1;
        }
      unfold_from(placed);
    }
    // Unfolded triangles may stick out of [0,1]^2 where the island sits at
    // the atlas's edge (bunny: 5 islands failed so): shift it back inside.
    Vec2 lo{kInf, kInf}, hi{-kInf, -kInf};
    for (const Vec2& p : uv_) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    const Vec2 shift{std::max(0.0, -lo.x) - std::max(0.0, hi.x - 1),
                     std::max(0.0, -lo.y) - std::max(0.0, hi.y - 1)};
    for (Vec2& p : uv_) p = p + shift;
  }

  void unfold_from(std::vector<uint8_t>& placed) {
    auto known = [&](size_t tri, int k) { return slot_[tri][k] == kFixed || placed[slot_[tri][k]]; };
    for (size_t round = 0; round < free_.size(); ++round) {
      bool progress = false;
      std::vector<std::pair<size_t, Vec2>> found;
      for (size_t i = 0; i < free_.size(); ++i) {
        if (placed[i]) continue;
        Vec2 sum{0, 0};
        int count = 0;
        for (auto [tri, k] : around_[i]) {
          const int a = (k + 1) % 3, b = (k + 2) % 3;
          const RestTriangle& r = rest_[triangles_[tri]];
          if (!r.valid || !known(tri, a) || !known(tri, b)) continue;
          const std::array<Vec2, 3> c = corners(tri);
          // Complex numbers: uv_k = uv_a + (uv_b - uv_a) (x_k - x_a) / (x_b - x_a).
          const Vec2 e = r.x[b] - r.x[a], q = r.x[k] - r.x[a], d = c[b] - c[a];
          const double e2 = dot(e, e);
          const Vec2 ratio{(q.x * e.x + q.y * e.y) / e2, (q.y * e.x - q.x * e.y) / e2};
          sum = sum + c[a] + Vec2{d.x * ratio.x - d.y * ratio.y, d.x * ratio.y + d.y * ratio.x};
          ++count;
        }
        if (count) found.push_back({i, (1.0 / count) * sum});
      }
      for (auto& [i, p] : found) { uv_[i] = p; placed[i] = 1; progress = true; }
      if (!progress) break;
    }
  }

  // Start 4, when every other start folds (a fan open at a chart border,
  // a ring no convex combination fits): from the current placement, descend
  // on the untangling energy (untangle_energy.h), which is finite on folds,
  // lowering its eps as Garanzha et al. do, until every triangle is
  // positive. True when it got there; the patch then minimises as usual.
  bool untangle(int max_rounds, int sweeps) {
    double worst = min_det();
    double eps = std::sqrt(1e-12 + 0.04 * std::pow(std::min(worst, 0.0), 2));
    for (int round = 0; round < max_rounds; ++round) {
      const double before = untangle_total(eps);
      for (int s = 0; s < sweeps; ++s) {
        const double start = untangle_total(eps);
        for (size_t i = 0; i < free_.size(); ++i) untangle_vertex(i, eps);
        if (!(start - untangle_total(eps) > 1e-9 * start)) break;
      }
      const double after = untangle_total(eps);
      worst = min_det();
      // Positive is not enough: a just-unfolded patch is a set of slivers the
      // barrier descent grows only slowly; go on while the energy still falls.
      if (worst > 0 && !(before - after > 1e-3 * before)) return true;
      // A fold that survives a round at the smallest eps without the energy
      // moving will not go (the fixed ring admits no injective placement):
      // stop, so a hopeless patch costs a few rounds, not all of them.
      if (worst <= 0 && eps <= 1e-9 && !(before - after > 1e-6 * before)) return false;
      // Garanzha et al.'s schedule: eps follows how far the fold still is.
      const double sigma = std::max(1 - after / before, 0.1);
      const double mu = (1 - sigma) * detail::chi(worst, eps);
      eps = worst < mu ? 2 * std::sqrt(mu * (mu - worst)) : 1e-10;
    }
    return min_det() > 0;
  }

  // Coordinate descent on the symmetric Dirichlet energy, one free vertex at
  // a time, with a backtracking line search that never accepts a flip (the
  // energy is infinite there) nor a UV outside [0,1]^2.
  void minimise(int sweeps) {
    double total = energy();
    for (int s = 0; s < sweeps; ++s) {
      double before = total;
      for (size_t i = 0; i < free_.size(); ++i) {
        Vec2 grad{0, 0};
        double curvature = 0, local = 0;
        for (auto [tri, k] : around_[i]) {
          const RestTriangle& r = rest_[triangles_[tri]];
          if (!r.valid) continue;
          Vec2 g;
          double c;
          const auto uv = corners(tri);
          detail::gradient(r, uv, k, g, c);
          grad = grad + g;
          curvature += c;
          local += detail::energy(r, uv);
        }
        if (!(curvature > 0) || !(norm(grad) > 0)) continue;
        const Vec2 old = uv_[i];
        const Vec2 step = (-1.0 / curvature) * grad;
        auto local_energy = [&](Vec2 p) {
          if (!in_unit_square(p)) return kInf;
          uv_[i] = p;
          double e = 0;
          for (auto [tri, k] : around_[i]) e += energy_of(tri);
          return e;
        };
        double alpha = 1, best = local;
        Vec2 best_p = old;
        for (int h = 0; h < 30; ++h, alpha *= 0.5) {
          const double e = local_energy(old + alpha * step);
          if (e < best) { best = e; best_p = old + alpha * step; break; }
        }
        // A full step that worked may be too timid (the curvature estimate
        // is an upper bound near the barrier): try doubling it.
        if (alpha == 1 && best < local)
          for (double grow = 2; grow <= 16; grow *= 2) {
            const double e = local_energy(old + grow * step);
            if (!(e < best)) break;
            best = e;
            best_p = old + grow * step;
          }
        uv_[i] = best_p;
        total += best - local;
      }
      if (!(before - total > 1e-9 * before)) break;
    }
  }

 private:
  struct Use { uint32_t tri; uint8_t k; };

  double min_det() const {
    double worst = kInf;
    for (size_t i = 0; i < triangles_.size(); ++i) {
      const RestTriangle& r = rest_[triangles_[i]];
      if (r.valid) worst = std::min(worst, detail::jacobian(r, corners(i)).det());
    }
    return worst;
  }
  double untangle_total(double eps) const {
    double e = 0;
    for (size_t i = 0; i < triangles_.size(); ++i) {
      const RestTriangle& r = rest_[triangles_[i]];
      if (r.valid) e += detail::untangle_energy(r, corners(i), eps);
    }
    return e;
  }
  double untangle_local(size_t i, double eps) const {
    double e = 0;
    for (auto [tri, k] : around_[i]) {
      const RestTriangle& r = rest_[triangles_[tri]];
      if (r.valid) e += detail::untangle_energy(r, corners(tri), eps);
    }
    return e;
  }
  Vec2 untangle_grad(size_t i, double eps) const {
    Vec2 g{0, 0};
    for (auto [tri, k] : around_[i]) {
      const RestTriangle& r = rest_[triangles_[tri]];
      if (r.valid) g = g + detail::untangle_gradient(r, corners(tri), k, eps);
    }
    return g;
  }
  // One Newton step on vertex i (2x2 Hessian by central differences of the
  // exact gradient), gradient descent where that Hessian is not positive,
  // with backtracking that keeps the vertex in [0,1]^2.
  void untangle_vertex(size_t i, double eps) {
    const Vec2 old = uv_[i];
    const Vec2 g = untangle_grad(i, eps);
    if (!(norm(g) > 0)) return;
    double reach = 0;  // local length scale for the difference step
    for (auto [tri, k] : around_[i]) {
      const auto c = corners(tri);
      reach = std::max({reach, norm(c[1] - c[0]), norm(c[2] - c[1]), norm(c[0] - c[2])});
    }
    const double h = 1e-6 * std::max(reach, 1e-9);
    uv_[i] = old + Vec2{h, 0};
    const Vec2 gx1 = untangle_grad(i, eps);
    uv_[i] = old - Vec2{h, 0};
    const Vec2 gx0 = untangle_grad(i, eps);
    uv_[i] = old + Vec2{0, h};
    const Vec2 gy1 = untangle_grad(i, eps);
    uv_[i] = old - Vec2{0, h};
    const Vec2 gy0 = untangle_grad(i, eps);
    uv_[i] = old;
    const double hxx = (gx1.x - gx0.x) / (2 * h), hyy = (gy1.y - gy0.y) / (2 * h);
    const double hxy = 0.25 * ((gx1.y - gx0.y) + (gy1.x - gy0.x)) / h;
    const double det = hxx * hyy - hxy * hxy;
    Vec2 step;
    if (hxx > 0 && det > 0)
      step = {-(hyy * g.x - hxy * g.y) / det, -(-hxy * g.x + hxx * g.y) / det};
    else
      step = (-std::max(reach, 1e-9) / norm(g)) * g;
    const double e0 = untangle_local(i, eps);
    for (double alpha = 1; alpha > 1e-9; alpha *= 0.5) {
      const Vec2 p = old + alpha * step;
      if (!in_unit_square(p)) continue;
      uv_[i] = p;
      if (untangle_local(i, eps) < e0) return;
    }
    uv_[i] = old;
  }

  std::vector<uint32_t> free_;
  const std::vector<RestTriangle>& rest_;
  const std::vector<std::array<Vec2, 3>>& uvs_;
  const std::vector<uint8_t>& foreign_;  // per corner; may be empty
  std::vector<uint32_t> triangles_;
  std::vector<std::array<uint32_t, 3>> slot_;
  std::vector<std::vector<Use>> around_;
  std::vector<Vec2> uv_;
};


}  // namespace

UvRepairResult repair_uvs(const Soup& soup, const quality::Weld& weld,
                          const std::vector<int>& triangle_chart, double uv_per_length,
                          std::vector<std::array<Vec2, 3>>& uvs, const UvRepairOptions& options,
                          Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = soup.triangles.size();
  if (uvs.size() != n || triangle_chart.size() != n || weld.corner_vertex.size() != 3 * n)
    throw Error(ErrorCode::internal, "uv repair: sizes of soup, weld, charts and UVs differ");
  UvRepairResult r;
  if (n == 0 || !(uv_per_length > 0)) return r;
  progress.update("uv repair", 0);

  // The orientation a continuous map gives the soup's winding: the dominant one.
  double oriented = 0;
  for (const auto& uv : uvs) oriented += signed_area2(uv);
  const double orientation = oriented >= 0 ? 1 : -1;
  std::vector<RestTriangle> rest(n);
  for (size_t t = 0; t < n; ++t)
    rest[t] = detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2),
                                    uv_per_length, orientation);

  // Corners that landed on another chart than their triangle's: their own
  // UV lies on that chart, far from the triangle's other corners. Their
  // triangles are bad, so these corners are free and follow their copies on
  // the triangle's chart instead.
  std::vector<uint8_t> foreign;
  if (options.corner_chart) {
    if (options.corner_chart->size() != 3 * n)
      throw Error(ErrorCode::internal, "uv repair: corner_chart needs one chart per corner");
    foreign.assign(3 * n, 0);
    for (size_t c = 0; c < 3 * n; ++c) foreign[c] = (*options.corner_chart)[c] != triangle_chart[c / 3];
  }
  std::vector<uint8_t> bad = find_bad(rest, uvs, options);
  for (size_t c = 0; c < foreign.size(); ++c) bad[c / 3] |= foreign[c] && rest[c / 3].valid;
  if (options.only_triangles) {
    std::vector<uint8_t> allowed(n, 0);
    for (uint32_t t : *options.only_triangles)
      if (t < n) allowed[t] = 1;
    for (size_t t = 0; t < n; ++t) bad[t] &= allowed[t];
  }
  r.bad_triangles = size_t(std::count(bad.begin(), bad.end(), 1));
  const UvVertices verts = uv_vertices(weld, triangle_chart);
  const double median = median_stretch(rest, uvs);

  // UV vertices whose welded vertex also lives on another chart: their
  // copies across the seam may match by chance (§8 extends charts across
  // seams), and moving them would cut those pairs.
  std::vector<uint8_t> on_seam(verts.count(), 0);
  if (options.keep_seam_vertices) {
    std::vector<int> chart_of_weld(weld.vertex_count, -1);
    std::vector<uint8_t> weld_on_seam(weld.vertex_count, 0);
    for (size_t c = 0; c < 3 * n; ++c) {
      int& seen = chart_of_weld[weld.corner_vertex[c]];
      if (seen >= 0 && seen != triangle_chart[c / 3]) weld_on_seam[weld.corner_vertex[c]] = 1;
      seen = triangle_chart[c / 3];
    }
    for (size_t c = 0; c < 3 * n; ++c) on_seam[verts.of_corner[c]] = weld_on_seam[weld.corner_vertex[c]];
  }

  // Patches: the UV vertices of bad triangles, joined through those triangles.
  UnionFind uf(verts.count());
  std::vector<uint8_t> in_patch(verts.count(), 0);
  for (size_t t = 0; t < n; ++t) {
    if (!bad[t]) continue;
    for (int k = 0; k < 3; ++k) in_patch[verts.of_corner[3 * t + k]] = !on_seam[verts.of_corner[3 * t + k]];
    uf.unite(verts.of_corner[3 * t], verts.of_corner[3 * t + 1]);
    uf.unite(verts.of_corner[3 * t], verts.of_corner[3 * t + 2]);
  }
  std::unordered_map<uint32_t, std::vector<uint32_t>> groups;
  for (uint32_t v = 0; v < verts.count(); ++v)
    if (in_patch[v]) groups[uf.find(v)].push_back(v);
  std::vector<std::vector<uint32_t>> patches;
  for (auto& [root, members] : groups) patches.push_back(std::move(members));
  std::sort(patches.begin(), patches.end());  // deterministic order
  r.patches = patches.size();

  std::vector<uint8_t> moved_vertex(verts.count(), 0);
  struct PatchTime { double seconds; size_t patch, free_vertices, triangles; int rings; bool done; };
  std::vector<PatchTime> patch_times;
  for (size_t p = 0; p < patches.size(); ++p) {
    if ((p & 255) == 0) progress.update("uv repair", double(p) / double(patches.size()));
    const auto t_patch = std::chrono::steady_clock::now();
    std::vector<uint32_t> free_vertices = patches[p];
    bool done = false;
    enum { too_large, no_start, no_gain, sliver } why = no_start;
    int rings_tried = 0;
    size_t last_triangles = 0;
    for (int ring = 0; ring <= options.max_growth; ++ring) {
      rings_tried = ring + 1;
      const bool grown_after_repair = done;
      if (free_vertices.size() > options.max_patch_vertices) { why = too_large; break; }
      Patch patch(free_vertices, verts, rest, uvs, foreign);
      last_triangles = patch.triangles().size();
      const double before = patch.original_energy();
      // Only small islands: a large one is a whole chart (a plate traced
      // mirrored), and laying it down anew would move it over other charts.
      if (options.island_start && !patch.has_fixed_corner() &&
          patch.triangles().size() <= options.island_max_triangles)
        patch.start_island();
      else patch.start_at_copies();
      if (!std::isfinite(patch.energy())) patch.start_tutte(500);
      if (!std::isfinite(patch.energy())) {
        patch.start_at_copies();  // vertices no triangle reaches keep their copies' mean
        patch.start_unfolding();
      }
      if (options.untangle && !std::isfinite(patch.energy())) {
        patch.start_at_copies();
        patch.untangle(options.untangle_rounds, 50);
      }
      why = no_start;
      bool improved = false;
      if (std::isfinite(patch.energy())) {
        patch.minimise(options.max_sweeps);
        const double after = patch.energy();
        why = !(after < before) ? no_gain : sliver;
        if (std::isfinite(after) && after < before && patch.unfolded()) {
          for (size_t i = 0; i < patch.free_vertices().size(); ++i) {
            const uint32_t v = patch.free_vertices()[i];
            moved_vertex[v] = 1;
            for (uint32_t e = verts.start[v]; e < verts.start[v + 1]; ++e) {
              const uint32_t c = verts.corners[e];
              uvs[c / 3][c % 3] = patch.uv(i);
            }
          }
          done = improved = true;
          // Still stretched: the fixed ring itself is squeezed (lines that
          // converged over a whole region); one more ring gives it room,
          // starting from this solution, kept only if it lowers the energy.
          bool still_bad = false;
          const bool may_grow = options.grow_while_bad &&
                                (options.grow_while_bad_max_vertices == 0 ||
                                 patch.free_vertices().size() <= options.grow_while_bad_max_vertices);
          if (may_grow)
            for (uint32_t t : patch.triangles()) still_bad |= is_bad(rest[t], uvs[t], median, options);
          if (!still_bad) break;
        }
        // No better, or still a sliver: the fixed surroundings themselves
        // constrain the patch too much; one more ring gives it room.
      }
      if (grown_after_repair && !improved) break;  // the last repair stands
      // Grow by one ring: every UV vertex of the patch's triangles is free.
      for (uint32_t t : patch.triangles())
        for (int k = 0; k < 3; ++k)
          if (!on_seam[verts.of_corner[3 * t + k]]) free_vertices.push_back(verts.of_corner[3 * t + k]);
      std::sort(free_vertices.begin(), free_vertices.end());
      free_vertices.erase(std::unique(free_vertices.begin(), free_vertices.end()), free_vertices.end());
    }
    (done ? r.repaired_patches : r.failed_patches) += 1;
    patch_times.push_back({std::chrono::duration<double>(std::chrono::steady_clock::now() - t_patch).count(),
                           p, free_vertices.size(), last_triangles, rings_tried, done});
    if (!done) {
      // The triangles of the failed patch's seed, for a retry (only_triangles).
      for (uint32_t v : patches[p])
        for (uint32_t e = verts.start[v]; e < verts.start[v + 1]; ++e)
          r.failed_triangles.push_back(verts.corners[e] / 3);
    }
    if (!done && r.failed_detail.size() < 12) {
      // What a failed patch looked like at its last try, to tell causes apart.
      Patch last(free_vertices, verts, rest, uvs, foreign);
      size_t fixed_corners = 0, invalid = 0;
      for (uint32_t t : last.triangles()) invalid += !rest[t].valid;
      for (size_t i = 0; i < last.triangles().size(); ++i)
        for (int k = 0; k < 3; ++k)
          fixed_corners += !std::binary_search(free_vertices.begin(), free_vertices.end(),
                                               verts.of_corner[3 * last.triangles()[i] + k]);
      r.failed_detail.push_back(
          {{"first_triangle", verts.corners[verts.start[patches[p][0]]] / 3},
           {"seed_vertices", patches[p].size()},
           {"free_vertices", free_vertices.size()},
           {"triangles", last.triangles().size()},
           {"fixed_corners", fixed_corners},
           {"degenerate_3d", invalid},
           {"reason", why == too_large ? "too_large" : why == no_start ? "no_start"
                                       : why == no_gain ? "no_gain" : "sliver"}});
    }
    if (!done) {
      (why == too_large ? r.failed_too_large : why == no_start ? r.failed_no_start
                                           : why == no_gain ? r.failed_no_gain : r.failed_sliver) += 1;
    }
  }

  const size_t shown = std::min<size_t>(3, patch_times.size());
  std::partial_sort(patch_times.begin(), patch_times.begin() + shown, patch_times.end(),
                    [](const PatchTime& a, const PatchTime& b) { return a.seconds > b.seconds; });
  for (size_t i = 0; i < shown; ++i) {
    const PatchTime& pt = patch_times[i];
    r.slowest_patches.push_back({{"seconds", pt.seconds},
                                 {"first_triangle", verts.corners[verts.start[patches[pt.patch][0]]] / 3},
                                 {"seed_vertices", patches[pt.patch].size()},
                                 {"free_vertices", pt.free_vertices},
                                 {"triangles", pt.triangles},
                                 {"rings", pt.rings},
                                 {"repaired", pt.done}});
  }
  r.repaired_vertices = size_t(std::count(moved_vertex.begin(), moved_vertex.end(), 1));
  for (size_t t = 0; t < n; ++t)
    r.repaired_triangles += moved_vertex[verts.of_corner[3 * t]] ||
                            moved_vertex[verts.of_corner[3 * t + 1]] ||
                            moved_vertex[verts.of_corner[3 * t + 2]];
  const std::vector<uint8_t> still_bad = find_bad(rest, uvs, options);
  r.bad_triangles_after = size_t(std::count(still_bad.begin(), still_bad.end(), 1));
  std::sort(r.failed_triangles.begin(), r.failed_triangles.end());
  r.failed_triangles.erase(std::unique(r.failed_triangles.begin(), r.failed_triangles.end()),
                           r.failed_triangles.end());
  progress.update("uv repair", 1);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace soupuv::transfer
