// One row of the collocation operator's near matrix, its plain-rule part
// (private to the field module; collocation.cpp builds the matrix with it).
//
// Input : a collocation point x; a target leaf's near columns as NearColumns
//         (per column k: its triangle's centroid, its squared near radius
//         (SourceGeometry::is_near's (near_factor * radius)^2) and its m
//         quadrature points at index q * count + k); the rule's m weights.
// Output: val[k] = sum_q w_q / |x - p_qk|, rounded to float, and near[k] = 1
//         where |x - centroid_k|^2 < near_r2_k (SourceGeometry::is_near),
//         else 0. The caller replaces val[k] by the near rule where near[k].
// Method: four columns per AVX2 pass in double: 1 / sqrt from the float
//         estimate (_mm256 rsqrt, 12 bits) refined twice by Newton in double
//         (relative error ~1e-13, far below the float the matrix stores),
//         where double sqrt and divide cost ~5 cycles a point; a scalar loop
//         on other CPUs and for the last columns. The near test rounds as
//         is_near's scalar form (no fused multiply-add).
// Why:   this row loop was most of the charge's set-up (ogre, 124k
//        triangles: 422 M entries, 7.3 s of a 14.7 s set-up; docs/tuning.md,
//        session 38).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::field::detail {

struct NearColumns {
  size_t count = 0;
  std::vector<double> cx, cy, cz, near_r2;  // count each
  std::vector<double> px, py, pz;           // m * count: point q of column k at q * count + k
};

void plain_near_row(const NearColumns& c, int m, const double* weights, Vec3 x, float* val, uint8_t* near);

}  // namespace soupuv::field::detail
