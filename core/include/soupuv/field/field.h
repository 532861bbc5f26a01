// The field engine's public API (paper §7): charge a triangle soup so that its
// surface potential is constant, then trace field lines from its corners.
//
//   ChargeResult charges = solve_charges(soup, ChargeOptions{}, progress);
//   FieldLines lines = trace_field_lines(charges, corner_seeds(soup), TraceOptions{}, progress);
//
// The charge model: every (possibly refined) source triangle carries a total
// charge q_j spread uniformly over its area. Near a triangle its potential and
// field are evaluated in closed form (triangle_integrals.h); further away by
// the symmetric quadrature rule of `quadrature_degree` (quadrature.h); far away
// through the fast multipole method (evaluator.h). ChargeResult and FieldLines
// are plain data, so the pipeline can cache them; the FMM tree is rebuilt from
// a ChargeResult on demand (FieldEvaluator).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "soupuv/field/field_lines.h"
#include "soupuv/mesh.h"
#include "soupuv/progress.h"
#include "soupuv/soup.h"
#include "soupuv/vec.h"

namespace soupuv::field {

struct ChargeOptions {
  enum class Solver { krylov, robin_hood, dense_lu };
  Solver solver = Solver::krylov;
  // Target max-norm relative deviation of the surface potential from its mean.
  double tolerance = 1e-6;
  int quadrature_degree = 4;        // 2, 4 or 6 (3, 6, 12 points per triangle)
  // Taylor expansion order p of the FMM; 0: from the tolerance (the FMM's own
  // error must stay below it: measured max rel. error at theta 0.5 is
  // p=4: 5e-5, 6: 4e-6, 8: 4e-7, 10: 5e-8, see tests/core/field/fmm_test.cpp).
  int fmm_order = 0;
  double fmm_theta = 0.5;           // multipole acceptance: (r_a + r_b) < theta * distance
  int threads = 0;                  // 0: OpenMP default
  // With threads = 0, the Krylov solve runs on one thread below this many
  // triangles: its mat-vec is then a few ms split into ~6 fork/joins, and on
  // a loaded 2-core machine each join waits for a descheduled or spinning
  // thread (measured, n = 1,088 sphere: solve 0.18 s on 1 thread vs 0.36 s
  // on 2, CPU likewise; at 12,800 two threads win, 1.8 s vs 3.0 s wall).
  size_t krylov_parallel_min = 8000;
  // Triangles with area > refine_area_ratio * median area are split (midpoint
  // subdivision) until they are not; 0 disables refinement.
  double refine_area_ratio = 16.0;
  // Krylov: total mat-vecs (0: kKrylovIterationBudget); robin hood: charge
  // transfers (0: 200 * n).
  int max_iterations = 0;
  double max_seconds = 0;           // stop early after this long (0: no limit)
  // robin hood only: initial potentials by O(n^2) direct summation instead of the FMM.
  bool direct_initialization = false;
  // Krylov only. The GMRES iterations use an FMM of this lower order (same
  // tree, same exact near field); each outer defect-correction step applies
  // the full-order operator once (charge_krylov.cpp). >= fmm_order: no split.
  int krylov_inner_order = 4;
  // Relative 2-norm residual the first inner GMRES solve reaches (the cheap
  // operator is no more accurate than that); later ones, and the whole solve
  // when there is no order split, iterate until max |r| <= tolerance / 10.
  double krylov_inner_tolerance = 1e-4;
  // Source triangles per FMM leaf for the solve (the near field is a
  // precomputed sparse matrix, so larger leaves trade memory for fewer M2L).
  // Measured, 25,600-tri torus, solve CPU seconds (loaded machine): leaf 16
  // 16.2, 32 11.2, 64 8.2, 96 9.9. Near matrix ~1,500 floats per row at 64.
  int krylov_leaf_size = 64;
  // Triangles per block of the block-Jacobi preconditioner (source cells).
  int krylov_block_size = 128;
  // Krylov only: a coarse correction over the preconditioner's blocks before
  // the block-Jacobi step (charge_coarse.h): it removes the smooth modes
  // whose slow convergence made the iteration count grow with n.
  bool krylov_coarse_correction = true;
  // Overlap of the block-Jacobi blocks (restricted additive Schwarz,
  // collocation.h): a block also takes every triangle j with
  // A_ij >= krylov_overlap_ratio * A_ii for one of its rows i; 0: none.
  // Measured with the coarse correction, noisy 51,200 soup, 2 threads
  // (loaded machine): 0: 22 mat-vecs, 0.5: 21, 0.3: 13, 0.2: 10 (solve CPU
  // 9.2 -> 7.3 s), 0.12: 9 with a larger set-up.
  double krylov_overlap_ratio = 0.2;
  // How the true error is re-evaluated: direct summation up to this many
  // triangles, above it an FMM of order verify_order (0: fmm_order + 2, at
  // theta 0.5 about 10x below the solve's own FMM error) on the solver's
  // tree, with the exact near pairs of its precomputed near matrix.
  // Direct summation is O(n^2): at 13,000 triangles it took 2.3 s of a 8.3 s
  // map (valve of the corpus), the FMM check 0.2 s (docs/tuning.md).
  size_t verify_direct_max = 2000;
  int verify_order = 0;
};

// The Krylov solve's default effort: it stops after this many mat-vecs
// (GMRES iterations and outer steps together) even short of `tolerance`,
// and says so (converged false, the verified error in the diagnostics).
// Why: every corpus solve that converges does so within 19 (ogre 19, beast
// 17, the others 3-14); the two that do not converge quickly (bracket 68,
// bracket-exact 83: coplanar and intersecting slivers) give the same maps
// stopped at 16 or 31 mat-vecs as at 68 or 83, 1.2-1.4 s sooner
// (docs/tuning.md, "The charge's effort budget and lines that stop at the
// proxy, session 35"). Within it, GMRES stops as soon as its recent rate
// cannot reach the target in what is left of the budget (GmresOptions::
// reach_window): bracket and bracket-exact stop after 8 and 6 (docs/tuning.md,
// "A solve that cannot reach its target in its budget, session 37").
inline constexpr int kKrylovIterationBudget = 30;

struct ChargeResult {
  // The charged source geometry: the soup's triangles, large ones refined.
  std::vector<Vec3> positions;
  std::vector<Tri> triangles;
  std::vector<uint32_t> parent;     // soup triangle each source triangle came from
  std::vector<double> charges;      // total charge per source triangle; sum = 1
  int quadrature_degree = 4;
  int fmm_order = 8;
  double fmm_theta = 0.5;

  std::string solver;               // "krylov", "robin-hood", "robin-hood-direct-init", "dense-lu"
  int iterations = 0;
  double seconds = 0;               // wall time of the whole solve (incl. verification)
  double solve_seconds = 0;         // without the final verification
  // CPU time of the process (all threads) during the solve, without the
  // verification: on a shared machine wall time is inflated, this is not.
  double solve_cpu_seconds = 0;
  bool converged = false;
  // max_i |phi_i - mean(phi)| / mean(phi) over the collocation points (the
  // centroids), by a fresh evaluation: direct summation or a high-order FMM.
  double max_rel_potential_error = 0;
  std::string verified_by;          // "direct" or "fmm"
  double mean_potential = 0;
  // Convergence history: the solver's own error estimate after each iteration
  // (Krylov: the inner GMRES relative residual estimate, and after each outer
  // step the true max |1 - A q| of the full operator; robin hood: tracked
  // (max-min)/mean, sampled).
  std::vector<double> history;
  std::vector<double> history_seconds;
  std::vector<int> history_iterations;
  // Krylov: operator and preconditioner set-up (tree, near matrix, block LU),
  // mat-vecs with the cheap and the full FMM, entries of the near matrix.
  double setup_seconds = 0;
  int cheap_matvecs = 0, full_matvecs = 0;
  size_t near_entries = 0;
  size_t source_triangles = 0;
  size_t refined_triangles = 0;     // soup triangles that were split
  std::vector<std::string> warnings;
};

ChargeResult solve_charges(const Soup& soup, const ChargeOptions& options,
                           Progress& progress = Progress::none());

// A field line start: the trace begins one start offset (TraceOptions::
// start_offset) along the normal, on the chosen side.
struct TraceSeed {
  Vec3 position;
  Vec3 normal;
  int side = 0;          // +1 along normal, -1 against, 0: the side where |E| is larger
  uint32_t corner = 0;   // triangle * 3 + k, copied into FieldLines::corner
  // A point inside the seed's triangle (its centroid). The side test probes
  // slightly towards it: at a sharp edge, v - eps * n lies on the
  // neighbouring face's plane and would look like the outside.
  Vec3 interior;
  bool has_interior = false;
  // A length typical of the soup at the seed: the mean edge of the triangles
  // that meet there. 0: the mean edge of all source triangles.
  double scale = 0;
};

// The FMM order solve_charges uses for `tolerance` when fmm_order is 0.
int fmm_order_for_tolerance(double tolerance);

// One seed per soup triangle corner (triangle * 3 + k), side 0.
std::vector<TraceSeed> corner_seeds(const Soup& soup);
// One seed per vertex of an indexed mesh that some face uses (the paper's
// protocol for meshes: Table 5), along the sum of its faces' area-weighted
// normals, side 0; `corner` names the vertex's first corner (face * 3 + k).
std::vector<TraceSeed> vertex_seeds(const TriMesh& mesh);

struct TraceOptions {
  enum class Integrator { euler, midpoint };
  Integrator integrator = Integrator::midpoint;
  int max_steps = 100;
  double step = 0;           // nominal step length; 0: 2% of the source bounding-box diagonal
  // Epsilon, the distance from a seed to its line's first point: this
  // length for every seed, or (0) start_offset_fraction of each seed's scale.
  double start_offset = 0;
  // Why 0.03 of the local edge: a line climbs from epsilon to the proxy at
  // about 1.5x its distance per step (the steps near a surface are half the
  // distance to it), and those steps are the costly ones (every near
  // triangle in the rule); at 1e-3 of the mean source edge they were 30-45 %
  // of a map's evaluations. The local scale keeps a small part of a
  // multi-scale soup (a sphere a tenth the size of its neighbours) from
  // starting tens of its own edges off. Measured on the corpus, the shared
  // samples and unseen soups (docs/tuning.md, "Where field lines start").
  double start_offset_fraction = 0.03;
  double stop_radius = 0;    // stop outside this sphere around the bbox centre; 0: 1.5 * half diagonal + 50 steps
  // Not empty: a line also ends (LineEnd::escaped) once a step takes it
  // outside this box (the pipeline's box beyond which no proxy can lie).
  Box3 stop_box;
  int threads = 0;
  // The tracer's own FMM accuracy. Measured by the trace engineer on the
  // 12,800-triangle torus, 400 points 1e-4 .. 0.4 above the surface, field
  // rel. error vs direct summation: p=6 theta=0.5 max 1.5e-3; p=6 theta=0.4
  // max 2.3e-4; p=7 theta=0.45 max 1.2e-4, median 2.4e-6.
  // Joint sweep (session 9, engineer near): Table 5 torus, 50 midpoint steps,
  // 1 thread, bench trace --repeat 2 (fastest run), CPU us per evaluation,
  // interleaved rounds on a loaded machine (same config: +-10 %); field
  // rel. error vs direct (max of the 320 samples along the lines):
  //   theta  p  | 12,800: us (rounds)        err     | 51,200: us    err    | M2L/eval at 12,800
  //   0.45   7  | 3.66 3.63 3.75 (3.39 4.13)  2.8e-5  | 2.77 3.21   4.0e-5   | 0.995
  //   0.50   8  | 3.67 3.60 3.34 (3.41)       3.5e-5  |                      | 0.735
  //   0.55   9  | 3.74 3.50 3.32 (3.48)       3.1e-5  | 2.80 3.22   3.5e-5   | 0.554
  //   0.60  10  | 3.74 3.62 3.26 (3.23 3.66)  3.3e-5  | 3.01 3.03   2.8e-5   | 0.416
  //   0.50 / 0.55 / 0.60 / 0.65 at p 7 / 8 / 9 / 10: 3.44 / 3.07 / 2.90 / 2.99 us,
  //   but 8.2e-5 / 6.2e-5 / 6.6e-5 / 1.3e-4: over half the 1e-4 budget;
  //   0.65 p 11 and 0.7 p 11-12: 3.5-3.6 us, 8.1e-5 .. 2.4e-4.
  //   Leaf 24 / 48 at theta 0.6 p 10: 3.48 / 3.98; leaf 48 at 0.5 p 8: 3.62.
  // In parentheses: single runs of earlier sweeps. 204,800 (no error
  // sampling), one run each: 0.45/7 2.69, 0.55/9 2.51, 0.60/10 2.94 us,
  // M2L/eval 0.90 / 0.49 / 0.38.
  // At equal error the cost is flat within the noise: the shorter near list
  // of a larger theta is paid back by the higher order's M2L and L2P (M2Ls
  // per evaluation fall 2.4x from 0.45/7 to 0.6/10, each costs several times
  // more: 286 coefficients at p 10, 120 at p 7). So the defaults stay p=7
  // theta=0.45, the lowest error at the same cost.
  int fmm_order = 7;
  double fmm_theta = 0.45;
  // Source triangles per FMM leaf: the tracer pays the near field at every
  // evaluation but the expansions only once per visited target cell. With
  // the float near field (tracer_kernels.h) 32 is the cheapest: 12,800 torus,
  // 50 midpoint steps, 1 thread, CPU per evaluation 16: 12.1 us, 32: 9.4 us
  // (M2L operations 1.40 M -> 0.63 M), field error max 5.0e-5 / 4.9e-5.
  int fmm_leaf_size = 32;
  bool keep_points = true;   // false: keep only the first and last point of each line
  bool adaptive_step = true; // shorten steps near the surface (off: fixed steps, for integrator studies)
  // The adaptive step near the surface: a fraction of the distance to the
  // nearest near-rule triangle, between 0.5 and near_step_fraction, as large
  // as keeps the line's turn per step (its curvature, measured over the last
  // step, times the step) within max_turn_per_step radians. Next to a flat
  // part the field is uniform and lines leave faster (a step below the
  // distance cannot reach a near triangle); where they bend, 0.5 as before.
  // near_step_fraction = 0.5: the fixed half-distance rule. Measured (Table 5
  // torus, 50 midpoint steps, 1 thread, loaded machine): trace CPU 12,800
  // 3.82 -> 3.3-3.5 s, 51,200 14.6 -> 12.0 s; crossing points with an offset
  // torus vs a fine reference, noisy 12,800 soup: p99 4.2e-3 -> 4.3e-3 edges
  // (1.4e-2 without the turn limit); segment-triangle crossings on a noisy
  // 3,200 soup unchanged (1,432 -> 1,431, all corner lines).
  double near_step_fraction = 0.9;
  double max_turn_per_step = 0.05;
  // Where the line runs straight, a near-surface step may also grow to this
  // many times the line's previous step (up to the nominal step), beyond the
  // near_step_fraction of the distance. Such a step is redone at the
  // distance rule when the field turned by more than max_turn_per_step
  // between its start and its midpoint, or when its segment meets a soup
  // triangle (Fmm::segment_crosses). Midpoint integrator only (the check
  // needs the midpoint's field); 0: the distance rule alone.
  // Why: from eps = 1e-3 edges the distance rule (x1.9 per step at most)
  // took ~14 steps to leave the near zone, each with ~90 near triangles per
  // evaluation: ~70 % of the trace time at 204,800 triangles.
  // Measured (soupuv-bench step-rule; p99 shift of the crossing points with
  // offset surfaces at 0.05 / 0.2 against a fine reference, mean edges),
  // growth 0 -> 16, 50 steps of 0.02 | of the default 2 % of the diagonal:
  //   torus 12,800            2.5e-3 / 1.9e-3 -> 2.6e-3 / 1.9e-3 | 2.7e-3 / 4.3e-2 -> 4.0e-3 / 2.9e-2
  //   torus soup, noise 3 %   1.3e-3 / 1.0e-3 -> 1.3e-3 / 1.0e-3 | 1.4e-3 / 1.9e-2 -> 3.9e-3 / 1.9e-2
  //   torus soup, noise 13 %  5.2e-3 / 5.2e-3 -> 5.1e-3 / 5.6e-3 | 7.5e-3 / 1.7e-2 -> 7.2e-3 / 1.7e-2
  //   cube soup 4,800         1.5e-3 / 8.0e-4 -> 1.5e-3 / 8.0e-4 | 1.5e-3 / 6.8e-3 -> 2.3e-3 / 6.8e-3
  // with the same lines meeting the soup (inside the noise, next to their
  // seeds) and the same triangles whose corner lines spread > 3x. Without
  // the turn check the 13 % soup's p99 doubled (1.6e-2 at default steps) and
  // the pipeline's noisy 100k torus lost its UV stretch (L2 1.15 -> 1.92;
  // with the check 1.152, as the distance rule's 1.153). 4 and 64 measure
  // as 16; 16 bounds how far one step's curvature estimate is trusted.
  double max_step_growth = 16;
  bool direct = false;       // evaluate the field by O(n) direct summation (the FMM's slow twin)
  // A line ends as LineEnd::trapped after this many steps in a row within
  // 2 start_offsets of the soup (adaptive steps only; 0: never). There the
  // step is its floor, start_offset, so such a line crawls along the surface:
  // it started where the field is only the charge solve's residual (inside
  // another closed part). Leaving lines pass 2 start_offsets in 2 steps.
  // A trapped line's corner falls back to the closest point, so its crawl
  // is wasted work: a fifth of a noisy scan's lines are trapped. At 16
  // instead of 32 the 124k scan's evaluations fell 9 % and its map took
  // 0.93x the time (paired runs), its figures unchanged; continuity moved
  // by at most 0.001 on the corpus. At 8 (16 % fewer evaluations) a line
  // of a noisy sphere that crawls 8 steps and escapes was lost
  // (docs/tuning.md, session 31).
  int trapped_steps = 16;
  // Set: a line ends (LineEnd::reached) at the first step whose segment
  // (start, end) this returns true for. The pipeline passes "crosses the
  // proxy": the transfer lands a line at its first proxy crossing, so the
  // steps after it were wasted (a third of them on valve, bracket and the
  // 65k scan). Called from the tracer's threads; the first segment, from
  // the seed to its start offset, is not tested.
  std::function<bool(Vec3, Vec3)> stop_crossing;
};

struct TraceStats {
  double seconds = 0;
  double build_seconds = 0;   // FMM tree and expansions (once)
  size_t evaluations = 0;     // field evaluations
  size_t steps = 0;
  size_t escaped = 0, step_limit = 0, stalled = 0, trapped = 0, reached = 0;
  // Steps beyond the distance rule (TraceOptions::max_step_growth): checked
  // against the soup, and those redone because their segment met a triangle.
  size_t grown_steps = 0, grown_steps_redone = 0;
  // Target cells whose local expansion the tracer computed (only where
  // lines went) and the M2L operations that cost: at small n a visible share.
  // m2l_terms: their contractions' multiply-adds (TracerField::m2l_terms).
  size_t expansions = 0, m2l_operations = 0, m2l_terms = 0;
};

FieldLines trace_field_lines(const ChargeResult& charges, const std::vector<TraceSeed>& seeds,
                             const TraceOptions& options, Progress& progress = Progress::none(),
                             TraceStats* stats = nullptr);

// The tracer behind trace_field_lines, for callers that decide the sides
// themselves between the probe and the trace: the FMM over the charged
// sources is built once (constructor) and serves every call.
//
//   FieldLineTracer tracer(charges, options);
//   std::vector<int> sides = tracer.probe_sides(seeds);  // +1 / -1 per seed
//   ... change some seeds' side (e.g. one side per component) ...
//   FieldLines lines = tracer.trace(seeds, progress);
//
// trace() probes the seeds whose side is 0 exactly as probe_sides does, so
// a seed traced with its probed side gives the same line either way.
// `charges` must outlive the tracer.
class FieldLineTracer {
 public:
  FieldLineTracer(const ChargeResult& charges, const TraceOptions& options);
  ~FieldLineTracer();
  FieldLineTracer(const FieldLineTracer&) = delete;
  FieldLineTracer& operator=(const FieldLineTracer&) = delete;

  // Per seed: its side when not 0, else the side (+1 along its normal, -1
  // against) where |E| is larger one start offset off the surface (two
  // field evaluations per such seed, in one batch).
  std::vector<int> probe_sides(const std::vector<TraceSeed>& seeds);
  FieldLines trace(const std::vector<TraceSeed>& seeds, Progress& progress = Progress::none());
  // Everything since construction: build, probes and traces.
  TraceStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace soupuv::field
