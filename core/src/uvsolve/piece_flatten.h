// One piece of a layout flattened from its own 3D shape (private to the UV
// solve; reembed.h and union_merge.h use it).
//
// Input : the soup, the rest scale (UV units per 3D length), the piece's
//         triangles, the layout (its corner vertices give the connectivity;
//         vertex_of, when given, maps layout vertices first, e.g. to join
//         two islands along a seam), the overlap sample spacing, a stretch
//         budget and SLIM's iteration count.
// Output: piece_mesh: the piece as a mesh of its own. Two triangles are
//         joined across an edge only when exactly two of the piece's
//         triangles use it, in opposite directions (an oriented manifold
//         edge); every other use is a boundary, and corners are one vertex
//         only when joined through such edges (a vertex where the piece
//         touches itself gets one copy per fan). A wrong weld (a bolt glued
//         to the plate it passes through) or a non-manifold joint so
//         becomes a cut, not a reason to give up.
//         flatten: for a piece that is one edge-connected, oriented
//         manifold of genus 0 with a boundary, LSCM (Lévy et al. 2002)
//         turned to the soup's orientation and scaled to the rest area, then
//         SLIM on the symmetric Dirichlet energy (from ARAP when LSCM folds
//         a sliver); kept when no triangle flips, the L2 stretch against
//         each soup triangle's own shape (as eval/uvmetrics.py measures)
//         is within the budget and at most kLapShare of its samples are
//         covered twice. On `overlap` the flattened piece is returned too.
//         SLIM stops early on a piece whose stretch will not reach the
//         budget at its current rate (refused as `stretch`).
// Cost  : one sparse LSCM factorisation and SLIM's per piece.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "atlas/chart_mesh.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"
#include "transfer/sym_dirichlet.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

enum class Outcome { kept, parts, topology, flip, stretch, overlap };

// One finished piece: its triangles, each corner's vertex and the vertices' UVs.
struct Piece {
  std::vector<uint32_t> tris;
  std::vector<std::array<uint32_t, 3>> corner;
  std::vector<Vec2> uv;
};

// A piece as a mesh of its own (joins: see above).
struct PieceMesh {
  atlas::ChartMesh chart;                                  // positions: mean of the joined soup corners
  std::vector<std::array<uint32_t, 3>> triangles;          // local vertices
  std::vector<transfer::detail::RestTriangle> rest;
  std::vector<std::vector<uint32_t>> neighbours;           // across joined edges
  std::vector<uint32_t> component;                         // edge-connected parts
  uint32_t components = 0;
};

PieceMesh piece_mesh(const Soup& soup, double uv_per_length, const std::vector<uint32_t>& tris, const UvLayout& L,
                     const std::vector<uint32_t>* vertex_of = nullptr);

// Joins triangle t's two corners on welded pair p to the other triangle's
// for piece_mesh's vertex_of: each of t's layout vertices there not joined
// yet maps to the other's, and is appended to `touched` (to be reset).
void join_across(const geometry::AdjacentPair& p, uint32_t t, const UvLayout& L, std::vector<uint32_t>& vertex_of,
                 std::vector<uint32_t>& touched);
// Genus 0 with at least one boundary loop: LSCM can flatten it.
bool flattenable(const atlas::ChartMesh& chart);

// On a `stretch` refusal, *stretch_floor (when given) receives the least
// L2 stretch the piece was heading for: the stretch where SLIM stopped,
// less its best recent rate for every iteration left (at least 1).
Outcome flatten(const PieceMesh& mesh, const std::vector<uint32_t>& tris, double cell, double max_stretch,
                int solve_iterations, Piece& out, double* stretch_floor = nullptr);

// The tests a flattened piece is kept on (no flip is the caller's): its L2
// stretch against the soup within max_stretch (else `stretch`, the
// stretch in *stretch_floor) and at most kLapShare of its samples covered
// twice (else `overlap`, the piece in `out`); `kept` fills `out`.
Outcome judge_piece(const PieceMesh& mesh, const std::vector<uint32_t>& tris, std::vector<Vec2> uv, double cell,
                    double max_stretch, Piece& out, double* stretch_floor = nullptr);

// What flattening a piece of `size` triangles costs, in the units the
// union merge's and the seam straightening's budgets count: its size, times
// sqrt(size / 3,000) above 3,000 triangles, where the sparse factorisations
// fill in and a triangle costs more. Counting triangles alone let a
// few-island map (stanford-bunny, 69k triangles) spend 30 s on 21 unions of
// 35-70k triangles, four times its trace; measured at 18-32 µs per unit at
// every size (docs/tuning.md, session 43).
size_t flatten_cost(size_t size);

// Sander's L2 stretch of triangles' UV corners against their soup
// triangles' own shapes (rest[k] and corners[k]; invalid rest triangles are
// skipped), normalised as eval/uvmetrics.py normalises a map: the budget
// flatten() and the attachment (attach_islands.h) check.
double rest_stretch_l2(const std::vector<transfer::detail::RestTriangle>& rest,
                       const std::vector<std::array<Vec2, 3>>& corners);

}  // namespace soupuv::uvsolve::detail
