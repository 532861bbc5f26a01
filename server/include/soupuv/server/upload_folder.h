// A model that comes as a folder: a .gltf plus the files it names (multipart
// parts named "files", each part's filename a relative path), or a .zip of the
// folder. Everything lands below the job's model/ directory; nothing from the
// request can name a path outside it.
//
// Input : part filenames / a zip file on disk, the byte budget of the upload.
// Output: files under `dest`, the model's path relative to `dest`, or a 400/413
//         refusal (slug + one-line detail).
// Limits (zip): at most kMaxFolderEntries entries, names <= 255 bytes of plain
// relative path (no '..', no absolute path, no drive, no backslash, no
// symlink entry), the bytes actually decompressed counted against the budget
// (the sizes a zip declares are not trusted: a zip bomb stops at the budget),
// and a compression ratio above kMaxZipRatio refused per entry.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace soupuv::server {

constexpr size_t kMaxFolderEntries = 256;
constexpr uint64_t kMaxZipRatio = 1000;

struct FolderRefusal {
  int status = 400;
  std::string slug, detail;
};

// "" when `name` is a plain relative path (components of [A-Za-z0-9._ -+@()],
// none empty, "." or ".."); otherwise why not.
std::string unsafe_relative_path(const std::string& name);

// Unpacks `zip` into `dest` (created). `budget`: the bytes all entries may
// decompress to. On success `model` is the .gltf/.glb closest to the root
// (exactly one at that depth, else refused).
std::optional<FolderRefusal> unpack_zip(const std::filesystem::path& zip, const std::filesystem::path& dest,
                                        uint64_t budget, std::string& model);

}  // namespace soupuv::server
