// The tracer's field evaluator: the field of fixed charged sources at many
// moving points, on top of an Fmm's trees and interaction lists.
//
//   Fmm fmm(sources, options, region);       // trees and lists; no set_charges needed
//   TracerField tf(fmm, charges, threads);    // keeps a reference to fmm
//   int leaf = tf.locate(x, old_leaf);        // target leaf of x (old_leaf: a guess)
//   tf.prepare(leaves);                       // local expansions of these leaves
//   tf.field(leaf, xs, count, E, nearest);    // all xs lie in `leaf`
//
// Inputs: the Fmm's source tree, target tree, and per-target-cell M2L and
// near lists; one charge per source triangle. Outputs: E (added to) and,
// optionally, the distance to the nearest triangle that
// `SourceGeometry::is_near` the point (infinity if none), which the tracer
// uses to shorten steps.
//
// Why a separate evaluator: the sources never move while tracing, so a step
// must only pay the target side.
//  - Local expansions are computed lazily, only for target cells a tracer
//    visits (and their ancestors): the target tree over the whole stop region
//    has many cells around the surface that no line ever enters, and M2L there
//    was most of the cost of Fmm::set_charges. A cell's M2Ls run in batched
//    calls, eight sources per SIMD pass (tracer_m2l.h), each source at the
//    lowest order that keeps the pair's truncation error within that of the
//    worst pair the Fmm's acceptance test admits (m2l_order_for).
//  - The near field runs in single precision over float blocks of source
//    leaves (tracer_kernels.h: 8 triangles per SIMD group, coordinates relative
//    to the leaves' parent's centre, no padding between sibling leaves): the kernel adds the quadrature points of every
//    triangle that is not near and flags the rest as candidates, which are
//    re-checked in double and evaluated by the near rule: the closed
//    form (double, four triangles per AVX2 pass) only within 1.55 radii; from there to 2.25 radii the
//    degree-6 rule on the triangle's four midpoint children (float); to 4
//    radii the degree-6 rule. The model (sources.h) has the closed form to 2.5
//    radii; the tracer's cheaper bands keep every triangle within the model's
//    own worst per-triangle error (see tracer_field.cpp).
//  - Points that share a target leaf are evaluated together, block by
//    block, so a block is loaded into L1 once for all of them.
// Same model as Fmm::evaluate, the slow twin: equal to float rounding except in the
// bands, where the difference is below the model's quadrature error.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "soupuv/field/fmm.h"
#include "soupuv/vec.h"

namespace soupuv::field {

namespace tracer {
class FieldExpansion;
class BatchM2L;
}

class TracerField {
 public:
  // How a target cell's M2L sources are expanded: each at the order its
  // separation needs (per_pair), or all at the Fmm's order (full: the same
  // expansions as Fmm::evaluate, for comparisons).
  enum class M2lOrder { per_pair, full };

  // charges: one per source triangle (input order). threads: 0 = OpenMP default.
  TracerField(const Fmm& fmm, const std::vector<double>& charges, int threads = 0,
              M2lOrder m2l_order = M2lOrder::per_pair);
  ~TracerField();

  // Target leaf containing x, or -1 outside the target tree's root cube.
  // `hint`: a leaf x probably still lies in (the previous step's), checked first.
  int locate(Vec3 x, int hint = -1) const;

  // Computes the local expansions of these target leaves (and of their
  // ancestors) that are not computed yet. OpenMP inside; not concurrent with field().
  void prepare(const std::vector<int>& leaves);

  // Adds the field at x[0..count) to E[0..count). Every x must lie in `leaf`
  // (as returned by locate and passed to prepare; -1 is allowed for points
  // outside the tree). When
  // nearest is given, nearest[i] receives the distance from x[i] to the
  // nearest triangle evaluated by its near rule (infinity if none).
  void field(int leaf, const Vec3* x, int count, Vec3* E, double* nearest) const;

  size_t memory_bytes() const;
  // Target cells whose local expansion was computed, and M2L operations spent.
  size_t expansions() const { return expansions_; }
  size_t m2l_operations() const { return m2l_ops_; }
  // The M2Ls' multiply-adds in their contractions (sum over operations of
  // the pairs of coefficients an operation of its order couples): what the
  // per-pair order saves.
  size_t m2l_terms() const { return m2l_terms_; }

  // The order a pair of separation ratio rho = (r_target + r_source) /
  // distance is expanded at: the lowest q with rho^q <= theta^(p + 1),
  // within [min(2, p), p]. A Cartesian Taylor M2L truncated at total degree
  // q expands 1/|R + z| (|z| <= r_target + r_source) to degree q, whose
  // field error is of order rho^q / |R|^2 times the pair's charge; the
  // acceptance test (rho < theta) lets the worst admitted pair have
  // theta^p. Each lower-order pair so stays a factor theta below that
  // worst pair: bounding it by theta^p itself (one order less) doubled the
  // worst field error on a torus (tracer_field_trace_test.cpp), since the
  // many pairs inside the bound then all err as much as the worst one.
  // Pairs far inside pay less: at p = 7, theta = 0.45 a pair at rho = 0.3
  // takes q = 6 (924 of the contraction's 1,716 terms).
  static int m2l_order_for(double rho, double theta, int p);

 private:
  // Float blocks (tracer_kernels.h) hold the leaf children of one source
  // cell back to back, coordinates relative to that cell's expansion centre
  // mc: padding to the SIMD width once per block, not once per leaf (one
  // near-list slot in six was padding with a block per leaf). Block b's
  // groups start at blocks_[block]; its slots at slot_tri_[slot0] (the tree
  // position of each slot's triangle, -1 for padding).
  struct Block {
    Vec3 mc;
    int groups = 0;
    size_t block = 0, slot0 = 0;
  };
  // One source leaf: the slots [first_slot, first_slot + count) of block `block`.
  struct Span {
    int block = 0, first_slot = 0, count = 0;
  };
  // A target leaf's near list as runs of groups of one block, each group with
  // the lanes of the listed leaves selected (masks[mask0 + g]).
  struct NearRun {
    int block = 0, g0 = 0, groups = 0, mask0 = 0;
  };
  struct NearPlan {
    std::vector<NearRun> runs;
    std::vector<uint8_t> masks;
  };
  void build_near_plan(int leaf);

  // The triangles (tree positions ks[0..n)) the float kernel flagged as
  // possibly near x: adds their field at x to e[0..3) by the model's rule
  // (float rules via `batch`, summed when the caller flushes it) and, if
  // `nearest` is given, sets *nearest to the distance to the nearest of them
  // that is near (infinity if none). All candidates of a point at once: the
  // nearest triangle is searched last, from the one with the nearest
  // centroid, so few point-triangle distances are computed. `near`: scratch.
  struct RuleBatch;  // tracer_field.cpp
  void near_candidates(const int* ks, int n, Vec3 x, double* e, double* nearest, RuleBatch& batch,
                       std::vector<std::pair<int, double>>& near) const;
  // Field and nearest near triangle at a point outside the target tree.
  void field_outside(Vec3 x, Vec3* E, double* nearest) const;
  void upward_pass();

  const Fmm& fmm_;
  int m_;                                  // quadrature points per triangle
  std::vector<double> pq_;                 // quadrature point charges, tree order
  std::vector<float> blocks_;              // see Block
  std::vector<double> tri_charge_;         // per triangle, tree order
  struct NearTriangle;                     // tracer_field.cpp
  std::vector<NearTriangle> near_tris_;    // per triangle, tree order
  struct NearTest;                         // tracer_field.cpp
  std::vector<NearTest> near_test_;        // per triangle, tree order: what classifying a candidate reads
  std::vector<int> span_of_cell_;          // source cell -> index into spans_ (-1: not a leaf)
  std::vector<Span> spans_;
  std::vector<Block> block_list_;
  std::vector<int> slot_tri_;              // per block slot: tree position, -1 padding
  std::vector<NearPlan> plans_;            // per target cell; built with its expansion
  int threads_;
  int ncoef_;
  std::vector<double> M_;                  // multipole moments, ncoef_ per source cell
  std::vector<int> slot_;                  // per target cell: its expansion slot, or -1
  // Per slot: the local expansion (ncoef_ doubles), then the same as field
  // polynomials (tracer_l2p.h), in pages of kPageSlots slots. Growing the
  // store never moves or zeroes computed slots: a vector's resize copied and
  // zeroed the whole store serially at every growth, page-faulting fresh
  // memory each time; a page here is first touched by the threads that
  // compute its slots.
  static constexpr size_t kPageSlots = 1024;
  std::vector<std::unique_ptr<double[]>> pages_;
  size_t slots_ = 0, slot_doubles_ = 0;
  double* local(int slot) const { return &pages_[slot / kPageSlots][(slot % kPageSlots) * slot_doubles_]; }
  double* polynomials(int slot) const { return local(slot) + ncoef_; }
  std::unique_ptr<tracer::FieldExpansion> field_expansion_;
  // Per order q (index q; empty below the lowest), the batched M2L of
  // expansions truncated at q: the first size_for(q) coefficients.
  std::vector<std::unique_ptr<tracer::BatchM2L>> m2l_by_order_;
  M2lOrder m2l_order_;
  size_t expansions_ = 0, m2l_ops_ = 0, m2l_terms_ = 0;
};

}  // namespace soupuv::field
