// UV method dispatch for `soupuv map` (see uv_method.h).
#include "uv_method.h"

#include <array>

#include "cli.h"
#include "soupuv/baseline/box_projection.h"
#include "soupuv/errors.h"
#include "soupuv/quality/uv_metrics.h"

namespace soupuv::cli {

namespace {

// Quality figures for any method's UVs. Adjacency comes from welding corners
// that coincide up to 1e-6 of the bounding-box diagonal: exact for welded
// inputs; a noisy soup has (almost) no adjacency, so continuity is omitted
// there and adjacent_pairs says why.
nlohmann::json uv_diagnostics(const Soup& soup, const std::vector<Vec2>& uvs) {
  quality::CornerUvs corners(soup.triangles.size());
  for (size_t t = 0; t < corners.size(); ++t)
    corners[t] = {uvs[t * 3], uvs[t * 3 + 1], uvs[t * 3 + 2]};
  double tolerance = 1e-6 * bounding_box(soup).diagonal();
  auto adjacency = quality::metric_adjacency(soup, nullptr, tolerance);
  // to_json leaves continuity out when there are no adjacent pairs.
  nlohmann::json uv = quality::to_json(quality::uv_metrics(soup, corners, adjacency));
  uv["weld_tolerance"] = tolerance;
  return uv;
}

}  // namespace

MethodRun compute_uvs(const io::Asset& asset, const std::string& method, Progress& progress) {
  MethodRun run;
  if (method == "box") {
    baseline::BoxResult box = baseline::box_projection(asset.soup, {}, progress);
    run.corner_uvs = std::move(box.corner_uvs);
    run.diagnostics["stages"]["box"]["seconds"] = box.seconds;
    run.diagnostics["box"]["face_triangles"] = box.face_triangles;
  } else if (method == "field") {
    throw Error(ErrorCode::not_built,
                "--method field is not built yet (the field pipeline has not landed); use --method box");
  } else {
    throw UsageError{"--method must be box or field, not '" + method + "'"};
  }
  progress.update("metrics", 0.0);
  run.diagnostics["uv"] = uv_diagnostics(asset.soup, run.corner_uvs);
  progress.update("metrics", 1.0);
  return run;
}

}  // namespace soupuv::cli
