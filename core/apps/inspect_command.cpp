// `soupuv inspect IN`: what the loader sees in a file, as JSON on stdout.
#include <cstdio>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "soupuv/io/load.h"

namespace soupuv::cli {

namespace {

nlohmann::json parts(const io::Asset& asset) {
  std::set<int32_t> meshes, nodes, materials;
  std::set<std::pair<int32_t, int32_t>> primitives;
  for (const TriangleOrigin& o : asset.soup.origins) {
    meshes.insert(o.mesh);
    primitives.insert({o.mesh, o.primitive});
    if (o.node >= 0) nodes.insert(o.node);
    materials.insert(o.material);
  }
  return {{"meshes", meshes.size()},
          {"primitives", primitives.size()},
          {"nodes", nodes.size()},
          {"instances", asset.instances.size()},
          {"materials", materials.size()}};
}

}  // namespace

int run_inspect(const InspectArgs& args) {
  const std::string& input = args.input;
  io::LoadOptions options;
  options.allow_external_uris = args.external_files;
  io::Asset asset = io::load_file(input, options);
  const Soup& soup = asset.soup;
  Box3 box = bounding_box(soup);
  SharingStats sharing = sharing_stats(soup);
  nlohmann::json out = {
      {"file", input},
      {"format", format_name(asset.format)},
      {"triangles", soup.triangle_count()},
      {"vertices", soup.positions.size()},
      {"parts", parts(asset)},
      {"bounding_box", {{"min", {box.lo.x, box.lo.y, box.lo.z}},
                        {"max", {box.hi.x, box.hi.y, box.hi.z}},
                        {"diagonal", box.diagonal()}}},
      {"sharing", {{"corners", sharing.corners},
                   {"distinct_vertex_indices", sharing.distinct_vertex_indices},
                   {"distinct_positions", sharing.distinct_positions},
                   {"shared_index_fraction", sharing.shared_index_fraction},
                   {"is_soup", sharing.is_soup}}},
      {"dropped_degenerate", asset.dropped_degenerate},
      {"skipped_primitives", asset.skipped_primitives},
      {"geometry_hash", geometry_hash(soup)},
      {"warnings", soup.warnings},
  };
  std::printf("%s\n", out.dump(2).c_str());
  return kOk;
}

}  // namespace soupuv::cli
