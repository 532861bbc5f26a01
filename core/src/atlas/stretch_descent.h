// Descent on the chart's L2 stretch (Sander et al. 2001) from a valid
// flattening, usually ARAP's: ARAP aims at isometry face by face, but the
// figure that decides a merge and that the soup wears is the area-weighted L2
// stretch at the area-matched scale, which a big, curved chart (a merged
// pelt) can lower well below ARAP's by letting compressed parts grow.
//
// Inputs:  a disk ChartMesh, UVs without flipped faces, the number of sweeps.
// Output:  UVs whose L2 stretch (chart_stretch_l2) is no higher, with no face
//          flipped or collapsed (each move keeps every incident face's UV
//          area above a floor; the stretch of a face grows without bound as
//          its UV area shrinks, so the energy itself keeps faces open).
//          Boundary self-intersection is not prevented here: the caller
//          checks it, as for any flattening.
//
// Method: nonlinear Gauss-Seidel. The energy E = (sum A3 L2^2)(sum Auv) /
// (sum A3)^2 is scale-free; moving one vertex changes only its faces' terms,
// so each vertex in turn takes a backtracking step along the negative
// gradient of E (central differences of its faces' terms), accepted only
// when E drops and no incident face folds. Cost per sweep: O(faces); sweeps
// stop early once one gains less than 0.1 % of E.
#pragma once

#include <vector>

#include "chart_mesh.h"  // relative: the tests include this header by path

namespace soupuv::atlas {

std::vector<Vec2> descend_l2_stretch(const ChartMesh& chart, std::vector<Vec2> uv, int sweeps);

}  // namespace soupuv::atlas
