// Direct summation over all source triangles for every target.
#include "soupuv/field/direct.h"

#include <omp.h>

namespace soupuv::field {

void direct_sum(const SourceGeometry& sources, const std::vector<double>& q,
                const std::vector<Vec3>& x, std::vector<double>* phi, std::vector<Vec3>* E,
                int threads) {
  const long n = static_cast<long>(x.size());
  if (phi) phi->assign(n, 0.0);
  if (E) E->assign(n, Vec3{});
  const int nth = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for num_threads(nth) schedule(dynamic, 16)
  for (long i = 0; i < n; ++i) {
    double f = 0;
    Vec3 e{0, 0, 0};
    for (size_t j = 0; j < sources.size(); ++j) {
      if (q[j] == 0) continue;
      double fj = 0;
      Vec3 ej{0, 0, 0};
      unit_potential_field(sources, j, x[i], phi ? &fj : nullptr, E ? &ej : nullptr);
      f += q[j] * fj;
      e += q[j] * ej;
    }
    if (phi) (*phi)[i] = f;
    if (E) (*E)[i] = e;
  }
}

}  // namespace soupuv::field
