#include "atlas/stretch_descent.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "soupuv/geometry/triangle_stretch.h"

namespace soupuv::atlas {
namespace {

struct FaceTerms {
  double weighted_l2 = 0;  // A3 * L2^2
  double area_uv = 0;
};

}  // namespace

std::vector<Vec2> descend_l2_stretch(const ChartMesh& c, std::vector<Vec2> uv, int sweeps) {
  const int nv = static_cast<int>(uv.size());
  const int nf = static_cast<int>(c.tri.size());
  if (sweeps <= 0 || nf == 0) return uv;
  std::vector<std::vector<int>> faces_of(nv);
  for (int f = 0; f < nf; ++f)
    for (int v : c.tri[f]) faces_of[v].push_back(f);
  std::vector<std::array<Vec3, 3>> q(nf);
  std::vector<double> area3(nf);
  double total3 = 0;
  for (int f = 0; f < nf; ++f) {
    q[f] = {c.position[c.tri[f][0]], c.position[c.tri[f][1]], c.position[c.tri[f][2]]};
    area3[f] = 0.5 * norm(cross(q[f][1] - q[f][0], q[f][2] - q[f][0]));
    total3 += area3[f];
  }
  if (!(total3 > 0)) return uv;
  // Faces without 3D area carry no stretch; they only have to stay unfolded.
  auto terms = [&](int f, const std::vector<Vec2>& x) {
    const std::array<Vec2, 3> p = {x[c.tri[f][0]], x[c.tri[f][1]], x[c.tri[f][2]]};
    const geometry::TriangleStretch s = geometry::triangle_stretch(q[f], p);
    return FaceTerms{s.l2_squared * s.area3d, s.area_uv};
  };

  for (int sweep = 0; sweep < sweeps; ++sweep) {
    double stretch_sum = 0, uv_sum = 0;
    for (int f = 0; f < nf; ++f) {
      const FaceTerms t = terms(f, uv);
      if (!(t.area_uv > 0)) return uv;  // the start must be unfolded
      stretch_sum += t.weighted_l2;
      uv_sum += t.area_uv;
    }
    // A face may shrink to this fraction of its area-matched size, no further.
    const double scale = uv_sum / total3;
    double improved = 0;
    const double before = stretch_sum * uv_sum;
    for (int v = 0; v < nv; ++v) {
      const std::vector<int>& fs = faces_of[v];
      if (fs.empty()) continue;
      double local_stretch = 0, local_uv = 0, shortest = std::numeric_limits<double>::infinity();
      for (int f : fs) {
        const FaceTerms t = terms(f, uv);
        local_stretch += t.weighted_l2;
        local_uv += t.area_uv;
        for (int k = 0; k < 3; ++k) shortest = std::min(shortest, norm(uv[c.tri[f][k]] - uv[c.tri[f][(k + 1) % 3]]));
      }
      // E at a trial position of v (infinite when a face folds or collapses).
      auto energy_at = [&](Vec2 p) {
        const Vec2 saved = uv[v];
        uv[v] = p;
        double s = stretch_sum - local_stretch, u = uv_sum - local_uv;
        bool open = true;
        for (int f : fs) {
          const FaceTerms t = terms(f, uv);
          open &= t.area_uv > 1e-4 * area3[f] * scale || (area3[f] <= 0 && t.area_uv > 0);
          s += t.weighted_l2;
          u += t.area_uv;
        }
        uv[v] = saved;
        return open ? s * u : std::numeric_limits<double>::infinity();
      };
      const double e0 = stretch_sum * uv_sum;
      // Central differences: E is smooth wherever the faces are open, and a
      // vertex touches few faces, so four local evaluations are cheap.
      const double h = 1e-4 * shortest;
      if (!(h > 0)) continue;
      const Vec2 p0 = uv[v];
      const Vec2 grad{(energy_at({p0.x + h, p0.y}) - energy_at({p0.x - h, p0.y})) / (2 * h),
                      (energy_at({p0.x, p0.y + h}) - energy_at({p0.x, p0.y - h})) / (2 * h)};
      const double g = norm(grad);
      if (!(g > 0) || !std::isfinite(g)) continue;
      // First trial: a quarter of the shortest incident edge; then halve.
      double step = 0.25 * shortest / g;
      for (int tries = 0; tries < 10; ++tries, step *= 0.5) {
        const Vec2 p = p0 - step * grad;
        const double e = energy_at(p);
        if (e < e0) {
          uv[v] = p;
          double s = stretch_sum - local_stretch, u = uv_sum - local_uv;
          for (int f : fs) {
            const FaceTerms t = terms(f, uv);
            s += t.weighted_l2;
            u += t.area_uv;
          }
          stretch_sum = s;
          uv_sum = u;
          improved += e0 - e;
          break;
        }
      }
    }
    // Stop once a sweep gains less than 0.1 % of the energy.
    if (improved < 1e-3 * before) break;
  }
  return uv;
}

}  // namespace soupuv::atlas
