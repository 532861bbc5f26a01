// The charge solvers behind solve_charges (charge.cpp). Each takes the
// source geometry, the options and a result to fill (charges, iterations,
// history); the caller refines, normalises and verifies.
#pragma once

#include <memory>

#include "collocation.h"
#include "soupuv/field/field.h"
#include "soupuv/field/sources.h"

namespace soupuv::field {

// `op` receives the FMM collocation operator a solver built (null if none),
// so the verification can reuse its near matrix.
void solve_krylov(const SourceGeometry& src, const ChargeOptions& o, Progress& progress, ChargeResult& r,
                  std::unique_ptr<CollocationOperator>& op);
void solve_robin_hood(const SourceGeometry& src, const ChargeOptions& o, Progress& progress, ChargeResult& r,
                      std::unique_ptr<CollocationOperator>& op);
void solve_dense_lu(const SourceGeometry& src, const ChargeOptions& o, Progress& progress, ChargeResult& r);

}  // namespace soupuv::field
