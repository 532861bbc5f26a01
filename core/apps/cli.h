// Shared pieces of the soupuv CLI: the subcommands, their flags, exit codes.
#pragma once

#include <string>
#include <vector>

#include "soupuv/errors.h"
#include "soupuv/io/load.h"

namespace soupuv::cli {

// Exit codes, one per ErrorCode, documented in `soupuv --help`.
enum Exit : int {
  kOk = 0,
  kInternal = 1,
  kUsage = 2,
  kInvalidInput = 3,
  kUnsupported = 4,
  kLimitExceeded = 5,
  kNoTriangles = 6,
  kNotBuilt = 7,
  kIoError = 8,
  kCanceled = 130,  // like a shell's 128 + SIGINT, but reached by a clean exit
};

int exit_code(ErrorCode code);

// A usage mistake: printed with a hint to --help, exit kUsage.
struct UsageError {
  std::string message;
};

// Output files cannot be written: exit kIoError.
struct IoError {
  std::string message;
};

struct InspectArgs {
  std::string input;
  bool external_files = true;  // like map: files beside a .gltf are read (--no-external-files: off)
};
struct MapArgs;  // map_flags.h

int run_inspect(const InspectArgs& args);
int run_map(const MapArgs& args);

// Writes bytes to path through a temporary file and a rename, so that a
// reader (or a canceled run) never sees half a file. Throws IoError.
void write_file_atomically(const std::string& path, const void* data, size_t size);

// Throws IoError unless the folder that will hold `path` exists and is
// writable: checked before a long run, so a typo costs no minutes of work.
void check_writable_destination(const std::string& path);

// "glb", "gltf" or "drc": the input format as the diagnostics and inspect name it.
const char* format_name(io::Format f);

}  // namespace soupuv::cli
