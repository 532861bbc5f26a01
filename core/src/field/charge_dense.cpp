// Dense reference solve of eq. 5: assemble A (n x n) and LU-factorise it with
// partial pivoting (Eigen). O(n^2) memory and O(n^3) time: for benchmarks and
// tests only; refuses n > 12,800.
#include <Eigen/Dense>
#include <omp.h>

#include "charge_solvers.h"
#include "soupuv/errors.h"

namespace soupuv::field {

void solve_dense_lu(const SourceGeometry& src, const ChargeOptions& o, Progress& progress, ChargeResult& r) {
  const long n = static_cast<long>(src.size());
  if (n > 12800) throw Error(ErrorCode::limit_exceeded, "dense LU charge solve is limited to 12,800 triangles");
  const int nth = o.threads > 0 ? o.threads : omp_get_max_threads();
  Eigen::MatrixXd A(n, n);
#pragma omp parallel for num_threads(nth) schedule(static)
  for (long j = 0; j < n; ++j)
    for (long i = 0; i < n; ++i) A(i, j) = unit_potential(src, j, src.centroid[i]);
  progress.update("charge", 0.3);
  Eigen::VectorXd q = A.partialPivLu().solve(Eigen::VectorXd::Ones(n));
  r.solver = "dense-lu";
  r.iterations = 1;
  r.charges.assign(q.data(), q.data() + n);
}

}  // namespace soupuv::field
