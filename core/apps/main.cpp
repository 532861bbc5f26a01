// soupuv: command-line entry. Parses the subcommand, runs it, and turns every
// failure into one line `soupuv: <reason>` on stderr and a documented exit
// code — never an uncaught exception or a signal.
#include <cstdio>
#include <cstring>
#include <new>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"

namespace {

const char* kHelp = R"(soupuv — texture mapping for triangle soups

Usage:
  soupuv inspect IN [--no-external-files]
      Prints JSON about IN (glTF, GLB or Draco): triangles, parts (meshes,
      primitives, nodes, instances, materials), bounding box, vertex sharing
      (is it a soup?), dropped degenerate triangles, warnings.

  soupuv map IN -o OUT.glb [options]
      Gives every triangle UVs and writes a textured GLB that keeps the input's
      positions, nodes, meshes and materials.
      --method field|box     UV method (default: field). field is the
                             monopole field-line method (offset proxy + atlas,
                             field lines from every corner); box is the
                             tri-planar box projection baseline (paper §11).
      --diagnostics OUT.json diagnostics (proto/diagnostics.schema.json)
      --texture IMG          embed this PNG/JPEG as baseColorTexture instead of
                             the generated UV-check texture
      --texture-size N       size of the generated texture (UV check or re-bake;
                             default 1024)
      --rebake               fill the texture with the input's base colour (its
                             texture through its old UVs, or vertex colours)
                             at the same surface points; the default when the
                             input has a base-colour texture or vertex colours
      --no-rebake            the UV-check texture even then
      --draco                KHR_draco_mesh_compression output (lossless)
      --normals              also write flat per-triangle NORMALs
      --no-external-files    refuse a .gltf's buffers and images in files (by
                             default they are read from the .gltf's folder or
                             below it; never URLs, absolute paths or '..')
      --progress bar|json|none
                             bar: a progress bar when stderr is a terminal
                             (default); json: one {"stage":..,"fraction":..}
                             object per line on stderr; none: quiet
    field method options:
      --offset auto|F        proxy offset: auto (tightest enclosing proxy of a
                             ladder, default) or a fraction F of the diagonal
      --offset-abs L         proxy offset as an absolute length
      --resolution N         proxy grid cells along the longest axis (0 = auto)
      --proxy-edge L         proxy remeshing target edge length (0 = the offset)
      --chart-angle DEG      atlas: max normal deviation within a chart (70)
      --no-merge-charts      atlas: keep the segmented charts (merging neighbours
                             across smooth boundaries, for shorter seams, is on)
      --merge-charts         atlas: merge charts (the default; with the limits below)
      --merge-area F         ... a merged chart holds at most F of the surface (1)
      --no-relax-seams       atlas: keep the merged charts' seams (by default they
                             move to cheaper cuts on coarse soups, <= 8 soup
                             triangles per proxy face)
      --relax-seams          atlas: relax seams whatever the soup's density
      --merge-fill F         ... and fills at least F of its minimal rectangle (0)
      --merge-cone DEG       ... and its normals stay within a cone of DEG (120)
      --chart-stretch S      atlas: max L2 stretch of a chart before a split
      --pack-splits N        atlas: rounds of halving charts to pack tighter
      --weld-tolerance F     corners closer than F x diagonal are one vertex
                             (shared lines, sides, §8 neighbours; 0.002)
      --steps N              field-line step limit (default 100)
      --integrator euler|midpoint
      --solver krylov|robin-hood   charge solver (default krylov)
      --tolerance X          charge solve: max relative potential deviation
      --threads N            total threads (the field branch uses all of them,
                             the proxy branch half while it runs)
      --cache-dir DIR        reuse charges and field lines across runs and
                             processes (content-addressed)
      --seam-hints FILE      JSON [[[x,y,z],...],...]: polylines forced as seams
      --original FILE        welded original with the same triangle order, for
                             the continuity figure (else corners are welded)
      --debug-prefix P       also write P.proxy.glb (textured proxy),
                             P.lines.glb (field lines), P.uv.png (UV layout)
      --uv-layout FILE       also write the UV layout as a 1024 px PNG
      --no-uv-repair         skip the local UV repair (a post-process after
                             transfer that re-places the UVs around flipped or
                             sliver triangles; on by default, --uv-repair)
      --repair-stretch F     repair triangles stretched beyond F x the median (2)
      --repair-growth N      rings a repair patch may grow by to find a start (3)
      --no-untangle          repair without the untangling start (Garanzha et al.)
      --no-grow-while-bad    a repaired patch whose triangles are still badly
                             stretched keeps its first repair (by default it
                             grows by up to --repair-growth rings while that helps)
      --no-island-start      repair chart islands (no fixed corner) like other
                             patches, not from one triangle laid down isometrically
      --no-repair-split      leave triangles whose corners landed on two charts
                             to the repair's usual rules
      --strict-retry F       after failed repair patches, repair again on an edge
                             weld that leaves an edge unmatched when its second-best
                             partner is within F x its best (1.05; trades a
                             little continuity for flips; --no-strict-retry: off)
      --weld-corners         §8 neighbours and the repair weld corners by position
                             (--weld-tolerance) instead of matching edges
      --seed-weld-corners    shared field lines start from copies welded by
                             position alone (default: matched edges, then position)
      --seed-edge-fraction F ... that position weld joins copies closer than F x
                             their triangles' shortest edge (0.5)
      --repair-weld-lines    the repair moves each shared line's copies as one UV
                             vertex (default: the matched-edge weld's vertices)
      --no-reweld            leave copies of one field line that the repair put
                             at different UVs on one chart apart (by default they
                             are joined again where nothing folds)
      --reweld-density E     ... a joined triangle's symmetric Dirichlet energy
                             per area may reach E (8; 4 = isometric)
      --no-uv-solve          the previous UV chain after transfer (repair, reweld,
                             island relaxation, candidate search) instead of the
                             soup UV solve (cut, untangle, SLIM, split, pack)
      --uv-collapse-ratio F  the UV solve cuts triangles whose UV area is below F
                             x their rest area after untangling (0.05)
      --uv-untangle-iterations N  ARAP iterations on folded islands (8)
      --uv-solve-iterations N     SLIM iterations per island (10)
      --uv-overlap-samples F overlap samples per texel side (2)
      --no-island-relax      skip the island relaxation (a post-process after the
                             repair: each UV island re-flattened as a whole)
      --island-max-triangles N  ... it runs on soups of at most N triangles
                             (20000; 0 = any size)
      --candidate NAME:K=V,..  one more (proxy, atlas) candidate landed against the
                             same field lines; on small coarse soups the one with
                             the best welded continuity within flipped <= 0.5 %
                             and L2 <= 1.3 is kept (keys: angle, alt_angle,
                             no_alt_angles, stretch, merge_cone, merge_area,
                             merge_fill, merge_stretch, merge_sweeps, relax, relax_band, relax_stretch,
                             offset); repeatable; atlas.candidates in diagnostics
      --no-candidates        only this run's own proxy and atlas
      --candidate-max-triangles N  search on soups of at most N triangles (20000)
      --no-refine-intersections  --no-orient  --no-share-lines  --no-chart-fix
      --no-chart-neighbours

  soupuv capabilities --json
      Prints what this build offers, for programs (the server's probe):
      {"soupuv_version", "commands": [...], "map_flags": ["--method", ...]}.

  soupuv --help | --version

Exit codes:
  0 success              5 limit exceeded (too many triangles or bytes)
  1 internal error       6 no triangles to map
  2 usage error          7 feature not built yet
  3 invalid input        8 cannot read or write a file
  4 unsupported input    130 canceled (SIGINT or SIGTERM)
Errors print one line "soupuv: <reason>" on stderr.
)";

// `soupuv capabilities --json`: the commands and every map flag this build
// documents. The flags are read from the help text above, the one list of
// them the CLI keeps (until the flags come from one table: issue 23).
int run_capabilities(const std::vector<std::string>& args) {
  using soupuv::cli::UsageError;
  if (args.size() != 1 || args[0] != "--json") throw UsageError{"capabilities takes --json"};
  const std::string help = kHelp;
  const size_t map_at = help.find("  soupuv map "), end_at = help.find("  soupuv capabilities");
  const std::string map_help = help.substr(map_at, end_at - map_at);
  std::set<std::string> flags;
  static const std::regex flag_re("--[a-z][a-z0-9-]*");
  for (std::sregex_iterator it(map_help.begin(), map_help.end(), flag_re), e; it != e; ++it) flags.insert(it->str());
  flags.insert("-o");
  const nlohmann::json j = {{"soupuv_version", SOUPUV_VERSION},
                            {"commands", {"inspect", "map", "capabilities"}},
                            {"map_flags", flags}};
  std::printf("%s\n", j.dump().c_str());
  return soupuv::cli::kOk;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace soupuv::cli;
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty()) throw UsageError{"no command given"};
    if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
      std::fputs(kHelp, stdout);
      return kOk;
    }
    if (args[0] == "--version") {
      std::printf("soupuv %s\n", SOUPUV_VERSION);
      return kOk;
    }
    std::string command = args[0];
    args.erase(args.begin());
    if (command == "inspect") return run_inspect(args);
    if (command == "map") return run_map(args);
    if (command == "capabilities") return run_capabilities(args);
    throw UsageError{"unknown command '" + command + "'"};
  } catch (const UsageError& e) {
    std::fprintf(stderr, "soupuv: %s (see soupuv --help)\n", e.message.c_str());
    return kUsage;
  } catch (const IoError& e) {
    std::fprintf(stderr, "soupuv: %s\n", e.message.c_str());
    return kIoError;
  } catch (const soupuv::Error& e) {
    std::fprintf(stderr, "soupuv: %s\n", e.what());
    return exit_code(e.code());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "soupuv: out of memory\n");
    return kInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "soupuv: internal error: %s\n", e.what());
    return kInternal;
  }
}
