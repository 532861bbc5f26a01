// Re-embeds islands whose transferred image the solve cannot make injective
// (private to the UV solve).
//
// Input : the soup, the rest scale (UV units per 3D length), which islands
//         to redo (one flag per island), the overlap sample spacing `cell`
//         (overlap_split.h's samples), the pieces' stretch budget, SLIM's
//         iteration count and a layout.
// Output: every selected island replaced by pieces flattened from their own
//         3D shape: a piece that is an oriented, manifold surface of genus 0
//         with a boundary is flattened conformally (LSCM, Lévy et al. 2002),
//         then by SLIM on the symmetric Dirichlet energy (piece_flatten.h);
//         it is kept when no triangle flips and its L2 stretch is within
//         the budget (a piece that still laps over itself is kept for the
//         overlap split). Otherwise (or when the piece is not such a
//         surface) it is split in two by a geodesic Voronoi split of its
//         triangles from two far-apart seeds, steps across creases counted
//         longer, and each half is tried again; single triangles keep their
//         rest shape.
//         Pieces become islands (shared vertices split); their position is
//         left to the packer.
// Why   : the transfer decides which soup triangles form an island (few
//         islands, long continuous seams); where its image of an island
//         folds or laps over itself (a bolt's hidden shank landing on the
//         plate around it, a scan's noise), the island's own shape gives a
//         map with the same connectivity. Only what cannot be flattened
//         at all is cut, along short geodesic seams instead of around every
//         lapping triangle.
// Cost  : O(n log n) per island of n triangles (each level of splitting
//         solves every triangle once; a sparse factorisation per piece).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "soupuv/soup.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct ReembedFigures {
  size_t islands = 0;             // islands re-embedded
  size_t pieces = 0;              // pieces they became
  size_t singleton_pieces = 0;    // pieces of one triangle
  size_t split_topology = 0;      // splits because a piece was no genus-0 surface with a boundary
  size_t split_flip = 0;          // ... because its flattening flipped or failed
  size_t split_stretch = 0;       // ... because its L2 stretch exceeded the budget
  size_t lapping_pieces = 0;      // kept although they lap over themselves (left to overlap_split.h)
};

ReembedFigures reembed_islands(const Soup& soup, double uv_per_length, const std::vector<uint8_t>& selected,
                               double cell, double max_stretch, int solve_iterations, int threads,
                               UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
