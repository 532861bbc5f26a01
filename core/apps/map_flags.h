// The one table of `soupuv map` flags. Each row names a flag, the value it
// takes, its help and the check on that value, and says what it does to the
// run's arguments. From it come the parser (CLI11), the help text and
// `soupuv capabilities --json`; a flag exists exactly when it has a row.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "progress_report.h"
#include "uv_method.h"
#include "value_check.h"

namespace CLI {
class App;
}

namespace soupuv::cli {

// Everything `soupuv map` was asked to do.
struct MapArgs {
  std::string input, output, diagnostics, method = kDefaultMethod, texture;
  int texture_size = 1024;
  bool draco = false, normals = false;
  bool external_files = true;  // a .gltf's .bin and images beside it (--no-external-files: off)
  std::optional<bool> rebake;  // --rebake / --no-rebake; unset: when the input has a base colour
  ProgressMode progress = ProgressMode::bar;
  MethodFlags method_flags;  // the UV methods' own options (uv_method.h)
};

struct MapFlag {
  std::string names;   // CLI11 form: "-o,--output" or "--draco"
  std::string value;   // the value's name in the help ("F", "N", "DIR"); "" for a switch
  std::string group;   // help section
  std::string help;
  ValueCheck check;    // for flags with a value
  // Applies the flag (its value already checked; "" for a switch). Flags are
  // applied in command-line order, so a later flag wins over an earlier one.
  std::function<void(MapArgs&, const std::string&)> apply;
};

const std::vector<MapFlag>& map_flags();

// Adds every row of the table to `map` as an option writing into `args`.
void add_map_flags(CLI::App& map, MapArgs& args);

// Breaks help text into lines of at most `width` characters at spaces (CLI11
// indents every line after a newline to the description column).
std::string wrap(const std::string& text, size_t width);

// The table for programs: {"names": [...], "value", "group", "help", "check"} per flag.
nlohmann::json map_flags_json();

}  // namespace soupuv::cli
