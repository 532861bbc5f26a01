// Flattening of one disk chart: LSCM (Lévy et al. 2002) as the conformal
// start, then ARAP local/global iterations (Liu et al. 2008) toward isometry,
// then optionally sweeps of descent on the L2 stretch itself
// (stretch_descent.h).
//
// Inputs:  a ChartMesh that is a topological disk, ARAP iteration count, the
//          stretch budget and the stretch-descent sweeps (0 = none).
// Output:  a UV per local vertex, in units of 3D length (the chart is scaled
//          so its UV area equals its 3D area), and whether it is valid: no
//          flipped face, a boundary that does not cross itself (together these
//          make the map injective) and L2 stretch within the budget. On
//          failure `why` says which test failed and the caller splits the chart.
#pragma once

#include <string>
#include <vector>

#include "chart_mesh.h"  // relative: the tests include this header by path

namespace soupuv::atlas {

struct ChartParameterization {
  std::vector<Vec2> uv;
  bool ok = false;
  std::string why;          // "flip", "overlap", "stretch", "solver"
  double stretch_l2 = 0;    // chart's own L2 stretch at its area-matched scale
};

ChartParameterization parameterize_chart(const ChartMesh& chart, int arap_iterations,
                                         double max_stretch, int stretch_sweeps = 0);

// Exposed for tests: the pieces above on their own.
std::vector<Vec2> lscm(const ChartMesh& chart);
std::vector<Vec2> arap(const ChartMesh& chart, std::vector<Vec2> start, int iterations);
int count_flipped(const ChartMesh& chart, const std::vector<Vec2>& uv);
bool boundary_self_intersects(const ChartMesh& chart, const std::vector<Vec2>& uv);
// Sander et al. 2001 L2 stretch after scaling UV area to 3D area.
double chart_stretch_l2(const ChartMesh& chart, const std::vector<Vec2>& uv);

}  // namespace soupuv::atlas
