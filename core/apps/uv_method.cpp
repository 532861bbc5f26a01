// UV method dispatch for `soupuv map` (see uv_method.h): MapOptions (set by
// the flag table) -> soupuv::run_map, plus the optional debug files.
#include "uv_method.h"

#include <fstream>
#include <memory>

#include "cli.h"
#include "soupuv/cache/store.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"
#include "soupuv/io/texture.h"
#include "soupuv/quality/uv_layout.h"

namespace soupuv::cli {

namespace {

std::vector<atlas::SeamHint> read_seam_hints(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError{"cannot read seam hints " + path};
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw Error(ErrorCode::invalid_input, "seam hints " + path + ": " + e.what());
  }
  std::vector<atlas::SeamHint> hints;
  if (!j.is_array()) throw Error(ErrorCode::invalid_input, "seam hints: an array of polylines expected");
  for (const auto& line : j) {
    atlas::SeamHint h;
    if (!line.is_array()) throw Error(ErrorCode::invalid_input, "seam hints: a polyline is an array of [x,y,z]");
    for (const auto& p : line) {
      if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
        throw Error(ErrorCode::invalid_input, "seam hints: a point is [x,y,z]");
      h.points.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
    }
    hints.push_back(std::move(h));
  }
  return hints;
}

void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace

MethodRun compute_uvs(const io::Asset& asset, const std::string& method, const MethodFlags& flags,
                      Progress& progress) {
  MapOptions options = flags.options;
  if (method == "box") options.method = MapMethod::box;
  else if (method == "field") options.method = MapMethod::field;
  else throw UsageError{"--method must be box or field, not '" + method + "'"};

  std::unique_ptr<cache::Store> store;
  if (!flags.cache_dir.empty()) {
    store = std::make_unique<cache::Store>(cache::StoreOptions{.memory_bytes = size_t(256) << 20,
                                                               .directory = flags.cache_dir});
    options.cache = store.get();
  }
  io::Asset original;
  if (!flags.original.empty()) {
    original = io::load_file(flags.original);
    options.original = &original.soup;
  }
  if (!flags.seam_hints.empty()) options.atlas.seam_hints = read_seam_hints(flags.seam_hints);
  options.keep_debug = !flags.debug_prefix.empty();

  MapResult result = run_map(asset, options, progress);
  MethodRun run;
  run.corner_uvs = std::move(result.corner_uvs);
  run.diagnostics = std::move(result.diagnostics);

  if (!flags.uv_layout.empty()) write_bytes(flags.uv_layout, quality::uv_layout_png(run.corner_uvs, 1024));
  if (!flags.debug_prefix.empty()) {
    const std::string& p = flags.debug_prefix;
    write_bytes(p + ".uv.png", quality::uv_layout_png(run.corner_uvs, 1024));
    if (options.method == MapMethod::field) {
      write_bytes(p + ".proxy.glb", proxy_debug_glb(result.debug, io::uv_check_texture(1024).bytes));
      write_bytes(p + ".lines.glb", field_lines_glb(result.debug.lines));
    }
    run.diagnostics["debug_outputs"] = {{"prefix", p}};
  }
  return run;
}

}  // namespace soupuv::cli
