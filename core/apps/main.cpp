// soupuv: command-line entry. Declares the subcommands and their flags (map's
// from its table, map_flags.h) to CLI11, runs the chosen one, and turns every
// failure into one line `soupuv: <reason>` on stderr and a documented exit
// code — never an uncaught exception or a signal.
#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "soupuv/openmp_wait.h"
#include "cli.h"
#include "map_flags.h"

namespace {

using namespace soupuv::cli;

const char* kExitCodes = R"(Exit codes:
  0 success              5 limit exceeded (too many triangles or bytes)
  1 internal error       6 no triangles to map
  2 usage error          7 feature not built yet
  3 invalid input        8 cannot read or write a file
  4 unsupported input    130 canceled (SIGINT or SIGTERM)
Errors print one line "soupuv: <reason>" on stderr.)";

// `soupuv capabilities --json`: what this build offers, for programs (the
// server's probe reads "map_flags"): every name of every row of the map flag
// table, and the rows themselves with their value checks.
int print_capabilities(const CLI::App& app) {
  std::vector<std::string> commands, flags;
  for (const CLI::App* sub : app.get_subcommands({})) commands.push_back(sub->get_name());
  const nlohmann::json options = map_flags_json();
  for (const auto& row : options)
    for (const auto& name : row["names"]) flags.push_back(name.get<std::string>());
  const nlohmann::json j = {{"soupuv_version", SOUPUV_VERSION},
                            {"commands", commands},
                            {"map_flags", flags},
                            {"map_options", options}};
  std::printf("%s\n", j.dump().c_str());
  return kOk;
}

int run(int argc, char** argv) {
  CLI::App app{"soupuv — texture mapping for triangle soups", "soupuv"};
  app.footer(kExitCodes);
  app.require_subcommand(1);
  app.get_formatter()->column_width(32);
  bool version = false;
  app.add_flag("--version", version, "print the version");

  InspectArgs inspect_args;
  CLI::App* inspect = app.add_subcommand(
      "inspect",
      "Prints JSON about IN (glTF, GLB or Draco): triangles, parts (meshes, primitives, nodes, "
      "instances, materials), bounding box, vertex sharing (is it a soup?), dropped degenerate "
      "triangles, warnings.");
  inspect->description(wrap(inspect->get_description(), 76));
  inspect->add_option("IN", inspect_args.input, "the file to inspect")->required();
  inspect->add_flag_callback("--no-external-files", [&inspect_args] { inspect_args.external_files = false; },
                            "refuse a .gltf's buffers and images in files (read from its folder by default)");

  MapArgs map_args;
  CLI::App* map = app.add_subcommand(
      "map",
      "Gives every triangle UVs and writes a textured GLB (OUT.glb) that keeps the input's "
      "positions, nodes, meshes and materials.");
  map->description(wrap(map->get_description(), 76));
  map->add_option("IN", map_args.input, "the soup to map (glTF, GLB or Draco)")->required();
  add_map_flags(*map, map_args);
  map->get_option("--output")->required();

  bool json = false;
  CLI::App* capabilities = app.add_subcommand(
      "capabilities", "Prints what this build offers, for programs (the server's probe): "
                      "{\"soupuv_version\", \"commands\", \"map_flags\", \"map_options\"}.");
  capabilities->description(wrap(capabilities->get_description(), 76));
  capabilities->add_flag("--json", json, "JSON on stdout (the only form)")->required();

  // `soupuv`, `soupuv --help`, `soupuv help`: every command with every flag.
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h" || args[0] == "help")) {
    std::fputs(app.help("", CLI::AppFormatMode::All).c_str(), stdout);
    return kOk;
  }
  if (!args.empty() && args[0] == "--version") {
    std::printf("soupuv %s\n", SOUPUV_VERSION);
    return kOk;
  }
  // Named here, not as CLI11's "A subcommand is required".
  if (!args.empty() && args[0].rfind("-", 0) != 0) {
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) known = known || sub->check_name(args[0]);
    if (!known) throw UsageError{"unknown command '" + args[0] + "'"};
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {  // `soupuv map --help`: that command's flags
    std::fputs(app.help().c_str(), stdout);
    return kOk;
  } catch (const CLI::CallForAllHelp&) {
    std::fputs(app.help("", CLI::AppFormatMode::All).c_str(), stdout);
    return kOk;
  } catch (const CLI::ParseError& e) {
    throw UsageError{e.what()};
  }
  if (version) {
    std::printf("soupuv %s\n", SOUPUV_VERSION);
    return kOk;
  }
  if (inspect->parsed()) return run_inspect(inspect_args);
  if (map->parsed()) return run_map(map_args);
  return print_capabilities(app);
}

}  // namespace

int main(int argc, char** argv) {
  soupuv::exec_with_sleeping_openmp_waiters(argv);
  try {
    return run(argc, argv);
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
