// The `soupuv map` flag table (see map_flags.h) and its use by CLI11.
#include "map_flags.h"

#include <algorithm>
#include <cmath>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "soupuv/errors.h"

namespace soupuv::cli {

namespace {

const char* kGeneral = "Options";
const char* kField = "Field method options";
const char* kSolve = "UV solve options";

double num(const std::string& v) { return parse_number(v); }
int whole(const std::string& v) { return int(parse_number(v)); }
MapOptions& opt(MapArgs& m) { return m.method_flags.options; }

// A switch: no value.
MapFlag sw(std::string names, std::string group, std::string help,
           std::function<void(MapArgs&)> apply) {
  return {std::move(names), "", std::move(group), std::move(help), any_text(),
          [apply = std::move(apply)](MapArgs& m, const std::string&) { apply(m); }};
}

// A flag with a value named `value`, accepted by `check`.
MapFlag val(std::string names, std::string value, ValueCheck check, std::string group, std::string help,
            std::function<void(MapArgs&, const std::string&)> apply) {
  return {std::move(names), std::move(value), std::move(group), std::move(help), std::move(check),
          std::move(apply)};
}

std::vector<MapFlag> make_table() {
  using proxy::OffsetMode;
  return {
      // Input, output, method.
      val("-o,--output", "OUT.glb", any_text(), kGeneral, "the textured GLB to write (required)",
          [](MapArgs& m, const std::string& v) { m.output = v; }),
      val("--method", "M", one_of({"field", "box"}), kGeneral,
          "UV method (default: field). field is the monopole field-line method (offset proxy + "
          "atlas, field lines from every corner); box is the tri-planar box projection baseline "
          "(paper §11)",
          [](MapArgs& m, const std::string& v) { m.method = v; }),
      val("--diagnostics", "OUT.json", any_text(), kGeneral, "diagnostics (proto/diagnostics.schema.json)",
          [](MapArgs& m, const std::string& v) { m.diagnostics = v; }),
      val("--texture", "IMG", any_text(), kGeneral,
          "embed this PNG/JPEG as baseColorTexture instead of the generated UV-check texture",
          [](MapArgs& m, const std::string& v) { m.texture = v; }),
      // The writer checks that it is a power of two.
      val("--texture-size", "N", whole_number_in(64, 4096), kGeneral,
          "size of the generated texture (UV check or re-bake), a power of two (default 1024); the "
          "field method packs its islands for it (their padding is in its texels)",
          [](MapArgs& m, const std::string& v) {
            m.texture_size = whole(v);
            opt(m).uv_solve.texture_size = m.texture_size;
          }),
      sw("--draco", kGeneral, "KHR_draco_mesh_compression output (lossless)",
         [](MapArgs& m) { m.draco = true; }),
      sw("--normals", kGeneral, "also write flat per-triangle NORMALs", [](MapArgs& m) { m.normals = true; }),
      sw("--no-external-files", kGeneral,
         "refuse a .gltf's buffers and images in files (by default they are read from the .gltf's "
         "folder or below it; never URLs, absolute paths or '..')",
         [](MapArgs& m) { m.external_files = false; }),
      sw("--rebake", kGeneral,
         "fill the texture with the input's base colour (its texture through its old UVs, or vertex "
         "colours) at the same surface points; the default when the input has a base-colour texture "
         "or vertex colours",
         [](MapArgs& m) { m.rebake = true; }),
      sw("--no-rebake", kGeneral, "the UV-check texture even then", [](MapArgs& m) { m.rebake = false; }),
      val("--progress", "MODE", one_of({"bar", "json", "none"}), kGeneral,
          "bar: a progress bar when stderr is a terminal (default); json: one "
          "{\"stage\":..,\"fraction\":..} object per line on stderr; none: quiet",
          [](MapArgs& m, const std::string& v) { m.progress = parse_progress_mode(v); }),

      // Field method: proxy, atlas, field.
      val("--offset", "F", words_or({"auto"}, number_in(0, 1, true, true)), kField,
          "proxy offset: auto (tightest enclosing proxy of a ladder, default) or a fraction F of "
          "the diagonal",
          [](MapArgs& m, const std::string& v) {
            auto& p = opt(m).proxy;
            if (v == "auto") {
              p.offset_mode = OffsetMode::automatic;
            } else {
              p.offset_mode = OffsetMode::relative;
              p.offset = num(v);
            }
          }),
      val("--offset-abs", "L", number_in(0, HUGE_VAL, true), kField, "proxy offset as an absolute length",
          [](MapArgs& m, const std::string& v) {
            opt(m).proxy.offset_mode = OffsetMode::absolute;
            opt(m).proxy.offset = num(v);
          }),
      val("--resolution", "N", whole_number_in(0, 2048), kField,
          "proxy grid cells along the longest axis (0 = auto)",
          [](MapArgs& m, const std::string& v) { opt(m).proxy.resolution = whole(v); }),
      val("--proxy-edge", "L", number_in(0, HUGE_VAL), kField,
          "proxy remeshing target edge length (0 = the offset)",
          [](MapArgs& m, const std::string& v) { opt(m).proxy.target_edge_length = num(v); }),
      val("--proxy-max-triangles", "N", whole_number_in(1000, 1000000), kField,
          "proxy face budget: an offset whose proxy would exceed it is refused, automatic takes a looser rung (50000)",
          [](MapArgs& m, const std::string& v) { opt(m).proxy.max_triangles = static_cast<size_t>(whole(v)); }),
      val("--chart-angle", "DEG", number_in(0, 90, true), kField,
          "atlas: max normal deviation within a chart (70)",
          [](MapArgs& m, const std::string& v) { opt(m).atlas.max_normal_deviation_deg = num(v); }),
      sw("--no-merge-charts", kField,
         "atlas: keep the segmented charts (merging neighbours across smooth boundaries, for "
         "shorter seams, is on)",
         [](MapArgs& m) { opt(m).atlas.merge_charts = false; }),
      sw("--merge-charts", kField, "atlas: merge charts (the default; with the limits below)",
         [](MapArgs& m) { opt(m).atlas.merge_charts = true; }),
      val("--merge-area", "F", number_in(0, 1, true), kField,
          "... a merged chart holds at most F of the surface (1)",
          [](MapArgs& m, const std::string& v) { opt(m).atlas.merge_max_area_fraction = num(v); }),
      val("--merge-fill", "F", number_in(0, 1), kField,
          "... and fills at least F of its minimal rectangle (0)",
          [](MapArgs& m, const std::string& v) { opt(m).atlas.merge_min_fill = num(v); }),
      val("--merge-cone", "DEG", number_in(0, 180, true), kField,
          "... and its normals stay within a cone of DEG (120)",
          [](MapArgs& m, const std::string& v) { opt(m).atlas.merge_max_normal_deviation_deg = num(v); }),
      sw("--no-relax-seams", kField,
         "atlas: keep the merged charts' seams (by default they move to cheaper cuts on coarse "
         "soups, <= 8 soup triangles per proxy face)",
         [](MapArgs& m) { opt(m).atlas.relax_seams = false; }),
      sw("--relax-seams", kField, "atlas: relax seams whatever the soup's density",
         [](MapArgs& m) {
           opt(m).atlas.relax_seams = true;
           opt(m).relax_max_soup_per_proxy_face = 0;
         }),
      val("--chart-stretch", "S", number_in(1, HUGE_VAL), kField,
          "atlas: max L2 stretch of a chart before a split",
          [](MapArgs& m, const std::string& v) { opt(m).atlas.max_stretch = num(v); }),
      val("--pack-splits", "N", whole_number_in(0, 16), kField,
          "atlas: rounds of halving charts to pack tighter",
          [](MapArgs& m, const std::string& v) { opt(m).atlas.packing_split_rounds = whole(v); }),
      val("--weld-tolerance", "F", number_in(0, 0.1, false, true), kField,
          "corners closer than F x diagonal are one vertex (shared lines, sides, §8 neighbours; 0.002)",
          [](MapArgs& m, const std::string& v) { opt(m).weld_tolerance = num(v); }),
      sw("--weld-corners", kField,
         "§8 neighbours and the UV solve weld corners by position (--weld-tolerance) instead of "
         "matching edges",
         [](MapArgs& m) { opt(m).weld_by_edges = false; }),
      sw("--seed-weld-corners", kField,
         "shared field lines start from copies welded by position alone (default: matched edges, "
         "then position)",
         [](MapArgs& m) { opt(m).seed_weld_by_edges = false; }),
      val("--seed-edge-fraction", "F", number_in(0, HUGE_VAL), kField,
          "... that position weld joins copies closer than F x their triangles' shortest edge (0.5)",
          [](MapArgs& m, const std::string& v) { opt(m).seed_weld_edge_fraction = num(v); }),
      val("--steps", "N", whole_number_in(1, 100000), kField, "field-line step limit (default 100)",
          [](MapArgs& m, const std::string& v) { opt(m).trace.max_steps = whole(v); }),
      val("--line-start", "F", number_in(0, 1, true, true), kField,
          "field lines start F x the mean edge of their seed's triangles off the surface (0.03)",
          [](MapArgs& m, const std::string& v) { opt(m).trace.start_offset_fraction = num(v); }),
      val("--integrator", "NAME", one_of({"euler", "midpoint"}), kField, "field-line integrator",
          [](MapArgs& m, const std::string& v) {
            opt(m).trace.integrator = v == "euler" ? field::TraceOptions::Integrator::euler
                                                   : field::TraceOptions::Integrator::midpoint;
          }),
      val("--solver", "NAME", one_of({"krylov", "robin-hood"}), kField, "charge solver (default krylov)",
          [](MapArgs& m, const std::string& v) {
            opt(m).charge.solver = v == "krylov" ? field::ChargeOptions::Solver::krylov
                                                 : field::ChargeOptions::Solver::robin_hood;
          }),
      val("--tolerance", "X", number_in(0, 1, true, true), kField,
          "charge solve: max relative potential deviation",
          [](MapArgs& m, const std::string& v) { opt(m).charge.tolerance = num(v); }),
      val("--charge-iterations", "N", whole_number_in(1, 100000), kField,
          "charge solve (krylov): stop after N mat-vecs even short of --tolerance (default 30)",
          [](MapArgs& m, const std::string& v) { opt(m).charge.max_iterations = whole(v); }),
      val("--threads", "N", whole_number_in(1, 1024), kField,
          "total threads (the field branch uses all of them, the proxy branch half while it runs)",
          [](MapArgs& m, const std::string& v) { opt(m).threads = whole(v); }),
      val("--cache-dir", "DIR", any_text(), kField,
          "reuse charges and field lines across runs and processes (content-addressed)",
          [](MapArgs& m, const std::string& v) { m.method_flags.cache_dir = v; }),
      val("--seam-hints", "FILE", any_text(), kField, "JSON [[[x,y,z],...],...]: polylines forced as seams",
          [](MapArgs& m, const std::string& v) { m.method_flags.seam_hints = v; }),
      val("--original", "FILE", any_text(), kField,
          "welded original with the same triangle order, for the continuity figure (else corners "
          "are welded)",
          [](MapArgs& m, const std::string& v) { m.method_flags.original = v; }),
      val("--debug-prefix", "P", any_text(), kField,
          "also write P.proxy.glb (textured proxy), P.lines.glb (field lines), P.uv.png (UV layout)",
          [](MapArgs& m, const std::string& v) { m.method_flags.debug_prefix = v; }),
      val("--uv-layout", "FILE", any_text(), kField, "also write the UV layout as a 1024 px PNG",
          [](MapArgs& m, const std::string& v) { m.method_flags.uv_layout = v; }),
      sw("--no-refine-intersections", kField, "charge the soup as loaded (by default triangles are split along their intersections first, §12.1)",
         [](MapArgs& m) { opt(m).refine_intersections = false; }),
      sw("--no-orient", kField, "skip the §12.4 orientation (by default one traced side per welded component)",
         [](MapArgs& m) { opt(m).orient_sides = false; }),
      sw("--no-share-lines", kField, "one field line per corner from its own triangle, as in the paper (by default copies of one welded position share a line)",
         [](MapArgs& m) { opt(m).share_lines = false; }),
      sw("--no-stop-at-proxy", kField, "trace field lines past their first proxy crossing to the reach box (cached lines then serve any proxy offset)",
         [](MapArgs& m) { opt(m).stop_lines_at_proxy = false; }),
      sw("--no-chart-fix", kField, "skip the §8 fix of triangles whose corners landed on different charts",
         [](MapArgs& m) { opt(m).transfer.fix_chart_boundaries = false; }),
      sw("--no-chart-neighbours", kField, "the paper's per-triangle §8 rule (by default a triangle across a seam prefers the chart its welded neighbours use)",
         [](MapArgs& m) { opt(m).chart_fix_neighbours = false; }),

      // The soup UV solve.
      val("--uv-collapse-ratio", "F", number_in(0, 1, false, true), kSolve,
          "the UV solve cuts triangles whose UV area is below F x their rest area after untangling (0.05)",
          [](MapArgs& m, const std::string& v) { opt(m).uv_solve.collapse_ratio = num(v); }),
      val("--uv-reembed-max-stretch", "F", number_in(1, 10), kSolve,
          "a piece flattened again from its own shape, or a union of islands, is split or refused above this L2 "
          "stretch (1.25)",
          [](MapArgs& m, const std::string& v) { opt(m).uv_solve.reembed_max_stretch = num(v); }),
      val("--uv-untangle-iterations", "N", whole_number_in(0, 1000), kSolve,
          "ARAP iterations on folded islands (8)",
          [](MapArgs& m, const std::string& v) { opt(m).uv_solve.untangle_iterations = whole(v); }),
      val("--uv-solve-iterations", "N", whole_number_in(0, 1000), kSolve, "SLIM iterations per island (10)",
          [](MapArgs& m, const std::string& v) { opt(m).uv_solve.solve_iterations = whole(v); }),
      sw("--no-uv-attach", kSolve,
         "keep every small island apart (by default an island whose padding would take more texels than it does is "
         "attached rigidly to a neighbouring island where that folds, laps and stretches nothing)",
         [](MapArgs& m) { opt(m).uv_solve.attach_small_islands = false; }),
      sw("--no-uv-slit", kSolve,
         "refuse the union of two islands that has no flat map within the stretch budget (by default, where their "
         "seam is one loop or the union is closed, it is tried again with half the seam left open)",
         [](MapArgs& m) { opt(m).uv_solve.slit_unions = false; }),
      sw("--no-uv-straighten", kSolve,
         "leave the seams between islands where the transfer and the joins put them (by default a seam moves to "
         "its shortest course nearby where both islands flatten again)",
         [](MapArgs& m) { opt(m).uv_solve.straighten_seams = false; }),
      sw("--no-uv-sliver-stacks", kSolve,
         "keep stacks of slivers thinner than the noise in the islands the steps before gave them (by default each "
         "stack is laid out as one grid, its slivers ranked by height)",
         [](MapArgs& m) { opt(m).uv_solve.sliver_stacks = false; }),
      val("--uv-overlap-samples", "F", number_in(0.25, 8), kSolve, "overlap samples per texel side (2)",
          [](MapArgs& m, const std::string& v) { opt(m).uv_solve.overlap_samples_per_texel = num(v); }),
  };
}

}  // namespace

std::string wrap(const std::string& text, size_t width) {
  std::string out, line;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    start = end + 1;
  }
  return out + line;
}

const std::vector<MapFlag>& map_flags() {
  static const std::vector<MapFlag> table = make_table();
  return table;
}

void add_map_flags(CLI::App& map, MapArgs& args) {
  for (const MapFlag& f : map_flags()) {
    const MapFlag* row = &f;
    CLI::Option* o;
    if (f.value.empty()) {
      o = map.add_flag_callback(f.names, [row, &args] { row->apply(args, ""); }, wrap(f.help, 48));
    } else {
      o = map.add_option_function<std::string>(
          f.names, [row, &args](const std::string& v) { row->apply(args, v); }, wrap(f.help, 48));
      o->type_name(f.value);
      const ValueCheck check = f.check;
      if (!check.describe().empty() || check.kind != ValueCheck::Kind::text)
        o->check(CLI::Validator([check](std::string& v) { return check.check(v); }, check.describe()));
    }
    // Applied as each occurrence is parsed: command-line order decides
    // between opposing flags, as it always did.
    o->trigger_on_parse()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)->group(f.group);
  }
}

nlohmann::json map_flags_json() {
  nlohmann::json out = nlohmann::json::array();
  for (const MapFlag& f : map_flags()) {
    std::vector<std::string> names;
    for (std::string rest = f.names; !rest.empty();) {
      const size_t comma = rest.find(',');
      names.push_back(rest.substr(0, comma));
      rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
    }
    nlohmann::json row = {{"names", names}, {"group", f.group}, {"help", f.help}};
    if (f.value.empty()) {
      row["value"] = nullptr;
    } else {
      row["value"] = f.value;
      row["check"] = f.check.to_json();
    }
    out.push_back(row);
  }
  return out;
}

}  // namespace soupuv::cli
