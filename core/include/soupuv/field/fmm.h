// Fast multipole method for the potential and field of charged triangles
// (Laplace kernel), built once per source geometry and evaluated at arbitrary
// points: charge-solve collocation points or tracer particles.
//
//   Fmm fmm(sources, FmmOptions{.order = 8, .theta = 0.5}, region);
//   fmm.set_charges(q);            // P2M, M2M, M2L, L2L: O(n) per call
//   fmm.evaluate(x, &phi, &E);     // L2P + near field of x's target leaf
//
// Two octrees: the source tree over triangle centroids (leaves of at most
// leaf_size triangles; a cell's multipole covers its triangles' quadrature
// points) and a target tree over `region` (a cube around region and the
// sources), refined lazily during one dual-tree traversal so that target
// leaves are as small as the source cells they are near. The traversal
// records, per target cell, the source cells it takes by M2L
// ((r_a + r_b) < theta * distance) and, per target leaf, the source leaves it
// takes directly. The near field uses the sources' rule (sources.h): closed
// form next to a triangle, quadrature otherwise. Memory O(n): lists of cell
// indices and one expansion per cell; no n x n storage.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/field/sources.h"
#include "soupuv/field/taylor.h"
#include "soupuv/vec.h"

namespace soupuv::field {

struct FmmOptions {
  int order = 8;
  double theta = 0.5;
  int leaf_size = 32;      // triangles per source leaf
  int threads = 0;         // 0: OpenMP default
  // Target leaves may be this many times larger than the source leaves they
  // take directly: larger means fewer target cells (less M2L), more direct work.
  double target_coarsening = 2.0;
};

struct FmmStats {
  size_t source_cells = 0, source_leaves = 0, target_cells = 0;
  size_t m2l_pairs = 0, near_leaf_pairs = 0;
  double build_seconds = 0, upward_seconds = 0, m2l_seconds = 0, downward_seconds = 0;
};

class Fmm {
  // The tracer's batched evaluator reads the frozen expansions and near lists
  // directly (tracer_field.cpp): the sources never move while tracing.
  friend class TracerField;

 public:
  // `region`: where evaluation points will lie (empty: the sources' bounding box).
  // Keeps a reference to `sources`: it must outlive the Fmm.
  Fmm(const SourceGeometry& sources, const FmmOptions& options, Box3 region = {});
  // Targets known in advance (e.g. the collocation centroids): the target tree
  // is refined only where they are (cells of more than leaf_size targets).
  Fmm(const SourceGeometry& sources, const FmmOptions& options, const std::vector<Vec3>& targets);
  // The same trees and interaction lists as `other` (they do not depend on
  // the order) with expansions of another order: no rebuild. The charge
  // solver's cheap inner operator and its verification use it.
  Fmm(const Fmm& other, int order);

  // One charge per source triangle (input order). Recomputes all expansions.
  void set_charges(const std::vector<double>& charges);

  // Target leaf containing x, or -1 outside the target tree's root cube.
  int locate(Vec3 x) const;

  // Potential and/or field at x (either pointer may be null). When
  // nearest_close is given, it receives the smallest distance from x to a
  // triangle evaluated in closed form (infinity if none): tracers use it to
  // shorten steps near the surface.
  void evaluate(Vec3 x, double* phi, Vec3* E, double* nearest_close = nullptr) const;

  // Potential at x leaving out the triangles `sources.is_near` claims for the
  // closed form (the charge solver adds those from a precomputed sparse list).
  double potential_without_close(int leaf, Vec3 x) const;

  // Far field only: the target leaf's local expansion at x. The caller adds
  // every triangle of near_source_triangles(leaf) itself (the charge solver
  // keeps them as a precomputed sparse matrix).
  double far_potential(int leaf, Vec3 x) const;

  // True when the closed segment ab meets a source triangle (coplanar
  // segments do not count; see geometry::segment_crosses_triangle).
  bool segment_crosses(Vec3 a, Vec3 b) const;

  // Source triangles (input indices) a target leaf takes directly.
  std::vector<uint32_t> near_source_triangles(int leaf) const;

  const FmmStats& stats() const { return stats_; }
  const SourceGeometry& sources() const { return src_; }
  // Source leaves as ranges of source triangles (input indices), for
  // leaf-block preconditioners.
  std::vector<std::vector<uint32_t>> source_leaf_triangles() const;
  // The largest source cells of at most max_count triangles (or leaves), as
  // lists of source triangles: a partition of all triangles into spatially
  // compact blocks for block preconditioners.
  std::vector<std::vector<uint32_t>> source_blocks(int max_count) const;

 private:
  struct SourceCell {
    Vec3 center;          // box centre
    double half = 0;      // box half size
    Vec3 mc;              // expansion centre
    double radius = 0;    // covers all vertices of its triangles around mc
    int first = 0, count = 0;      // range in order_
    int child_first = -1, children = 0;
    int level = 0;
  };
  struct TargetCell {
    int targets = -1;      // known targets inside (-1: targets not known in advance)
    Vec3 center;
    double half = 0;
    int child_first = -1;  // 8 children in octant order
    int parent = -1;
    int level = 0;
  };

  void build_source_tree();
  // The dual-tree traversal that refines the target tree and fills m2l_ and
  // near_ (fmm.cpp): subtrees below a frontier are built in parallel.
  struct TargetBuild;
  void build_target_tree(Box3 region, const std::vector<Vec3>* targets);
  // Returns the distance to the nearest closed-form triangle when want_nearest
  // (a point-triangle distance per such triangle), else infinity.
  double near_part(int leaf, Vec3 x, double* phi, Vec3* E, bool skip_close, bool want_nearest) const;

  const SourceGeometry& src_;
  FmmOptions opt_;
  TaylorBasis basis_;
  int ncoef_;

  std::vector<uint32_t> order_;          // source triangles in tree order
  std::vector<SourceCell> scells_;
  std::vector<std::vector<int>> slevels_;
  std::vector<double> point_charge_;     // per quadrature point in tree order
  std::vector<Vec3> points_;             // quadrature points in tree order
  std::vector<double> tri_charge_;       // per triangle in tree order
  std::vector<double> M_;                // ncoef per source cell

  std::vector<TargetCell> tcells_;
  std::vector<Vec3> target_points_;      // known targets, split into cells as the tree refines
  std::vector<std::vector<int>> tlevels_;
  std::vector<std::vector<int>> m2l_;    // per target cell: source cells
  std::vector<std::vector<int>> near_;   // per target leaf: source leaves
  std::vector<double> L_;                // ncoef per target cell

  FmmStats stats_;
};

}  // namespace soupuv::field
