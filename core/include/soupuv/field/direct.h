// Direct O(n^2) summation of the charged-triangle potential and field: the
// slow twin of the FMM (same near/far rule, sources.h), used by tests, by the
// robin hood "direct initialisation" and to verify charge solutions.
#pragma once

#include <vector>

#include "soupuv/field/sources.h"

namespace soupuv::field {

// phi[i] and E[i] at x[i] from charges q (one per source triangle); either
// output may be null. OpenMP over targets.
void direct_sum(const SourceGeometry& sources, const std::vector<double>& q,
                const std::vector<Vec3>& x, std::vector<double>* phi, std::vector<Vec3>* E,
                int threads = 0);

}  // namespace soupuv::field
