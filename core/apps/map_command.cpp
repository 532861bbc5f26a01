// `soupuv map IN -o OUT.glb ...`: load, compute UVs with the chosen method,
// write the textured GLB and (optionally) the diagnostics JSON.
#include <chrono>
#include <cstdio>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "map_flags.h"
#include "progress_report.h"
#include "soupuv/bake/rebake.h"
#include "soupuv/io/load.h"
#include "soupuv/io/write.h"
#include "uv_method.h"

namespace soupuv::cli {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int run_map(const MapArgs& m) {
  // Checked before a long run, so a typo costs no minutes of work.
  check_writable_destination(m.output);
  if (!m.diagnostics.empty()) check_writable_destination(m.diagnostics);
  Progress progress = make_progress(m.progress);
  cancel_on_signals(progress);
  nlohmann::json stages = nlohmann::json::object();

  auto start = std::chrono::steady_clock::now();
  progress.update("load", 0.0);
  io::LoadOptions load_options;
  load_options.allow_external_uris = m.external_files;
  io::Asset asset = io::load_file(m.input, load_options);
  stages["load"]["seconds"] = seconds_since(start);
  progress.update("load", 1.0);

  // Checked before the (possibly long) UV computation, so a bad image fails fast.
  io::WriteOptions write_options;
  if (!m.texture.empty()) write_options.texture = io::texture_from_file(m.texture);
  write_options.check_texture_size = m.texture_size;
  write_options.draco = m.draco;
  write_options.normals = m.normals;

  MethodRun run = compute_uvs(asset, m.method, m.method_flags, progress);

  start = std::chrono::steady_clock::now();
  progress.update("write", 0.0);
  // The input's base colour carried onto the new map (soupuv/bake/rebake.h);
  // a user --texture wins over it.
  std::optional<bake::RebakeResult> baked;
  const bool rebake = m.texture.empty() && m.rebake.value_or(bake::has_base_color(asset));
  if (m.rebake.value_or(false) && !m.texture.empty()) throw UsageError{"--rebake and --texture exclude each other"};
  if (rebake) {
    baked = bake::rebake(asset, run.corner_uvs, {.size = m.texture_size, .padding = 4});
    write_options.texture = baked->texture;
    write_options.texture_name = "soupuv re-baked base colour";
    write_options.keep_colors = !baked->baked_colors;
  }
  io::WriteResult written = io::write_glb(asset, run.corner_uvs, write_options);
  progress.check_canceled();
  write_file_atomically(m.output, written.glb.data(), written.glb.size());
  stages["write"]["seconds"] = seconds_since(start);
  progress.update("write", 1.0);
  finish_progress(m.progress);

  // The map's warnings (they start with the soup's) and the writer's.
  std::vector<std::string> warnings = asset.soup.warnings;
  if (run.diagnostics.contains("warnings") && run.diagnostics["warnings"].is_array())
    warnings = run.diagnostics["warnings"].get<std::vector<std::string>>();
  if (baked) warnings.insert(warnings.end(), baked->warnings.begin(), baked->warnings.end());
  warnings.insert(warnings.end(), written.warnings.begin(), written.warnings.end());

  if (!m.diagnostics.empty()) {
    nlohmann::json d = run.diagnostics;
    d["soupuv_version"] = SOUPUV_VERSION;
    d["input"] = {{"file", m.input}, {"format", format_name(asset.format)},
                  {"hash", geometry_hash(asset.soup)}};
    d["soup"] = {{"triangles", asset.soup.triangle_count()},
                 {"vertices", asset.soup.positions.size()},
                 {"dropped_degenerate", asset.dropped_degenerate},
                 {"skipped_primitives", asset.skipped_primitives}};
    d["method"] = m.method;
    for (auto& [name, stage] : stages.items()) d["stages"][name] = stage;
    d["output"] = {{"file", m.output}, {"bytes", written.glb.size()},
                   {"meshes", written.meshes}, {"primitives", written.primitives},
                   {"vertices", written.vertices}, {"triangles", written.triangles},
                   {"draco", m.draco}, {"normals", m.normals}, {"attributes", written.attributes},
                   {"texture", {{"source", baked ? "rebake" : m.texture.empty() ? "uv_check" : "user"},
                                {"mime_type", write_options.texture ? write_options.texture->mime_type : "image/png"}}}};
    if (baked) d["output"]["rebake"] = baked->diagnostics();
    d["warnings"] = warnings;
    std::string text = d.dump(2) + "\n";
    write_file_atomically(m.diagnostics, text.data(), text.size());
  }
  // In json mode stderr belongs to the worker protocol; warnings are in the diagnostics.
  if (m.progress != ProgressMode::json)
    for (const std::string& w : warnings) std::fprintf(stderr, "soupuv: warning: %s\n", w.c_str());
  std::printf("wrote %s: %zu triangles, %zu vertices, method %s\n", m.output.c_str(),
              written.triangles, written.vertices, m.method.c_str());
  return kOk;
}

}  // namespace soupuv::cli
