// Folder uploads (see upload_folder.h). libzip reads the archive: it checks the
// central directory and gives each entry's stored attributes (symlinks are
// refused) and a stream whose decompressed bytes we count ourselves.
#include "soupuv/server/upload_folder.h"

#include <sys/stat.h>
#include <zip.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <memory>
#include <vector>

namespace soupuv::server {
namespace fs = std::filesystem;

std::string unsafe_relative_path(const std::string& name) {
  if (name.empty() || name.size() > 255) return "a file name must be 1-255 bytes";
  if (name.front() == '/') return "'" + name.substr(0, 80) + "' is absolute";
  size_t start = 0;
  while (start <= name.size()) {
    size_t end = name.find('/', start);
    if (end == std::string::npos) end = name.size();
    const std::string part = name.substr(start, end - start);
    if (part.empty() || part == "." || part == "..")
      return "'" + name.substr(0, 80) + "' is not a plain relative path (empty, '.' or '..' component)";
    for (unsigned char c : part)
      if (!(std::isalnum(c) || c == '.' || c == '_' || c == '-' || c == ' ' || c == '+' || c == '@' || c == '(' ||
            c == ')'))
        return "'" + name.substr(0, 80) + "' has a character outside [A-Za-z0-9._ -+@()]";
    start = end + 1;
  }
  return "";
}

namespace {

bool is_model_name(const std::string& n) {
  auto ends = [&](const char* e) {
    const size_t k = std::char_traits<char>::length(e);
    return n.size() > k && n.compare(n.size() - k, k, e) == 0;
  };
  return ends(".gltf") || ends(".glb");
}

struct ZipCloser {
  void operator()(zip_t* z) const { zip_discard(z); }
};
struct ZipFileCloser {
  void operator()(zip_file_t* f) const { zip_fclose(f); }
};

FolderRefusal bad_zip(const std::string& detail) { return {400, "invalid-zip", detail}; }

}  // namespace

std::optional<FolderRefusal> unpack_zip(const fs::path& zip, const fs::path& dest, uint64_t budget,
                                        std::string& model) {
  int err = 0;
  std::unique_ptr<zip_t, ZipCloser> archive(zip_open(zip.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &err));
  if (!archive) return bad_zip("the upload is not a readable zip archive");
  const zip_int64_t n = zip_get_num_entries(archive.get(), 0);
  if (n < 0) return bad_zip("the zip's central directory cannot be read");
  if (uint64_t(n) > kMaxFolderEntries)
    return bad_zip("the zip holds " + std::to_string(n) + " entries, more than " +
                   std::to_string(kMaxFolderEntries));
  fs::create_directories(dest);
  uint64_t total = 0;
  size_t best_depth = SIZE_MAX;
  int at_best = 0;
  std::vector<char> buf(1 << 16);
  for (zip_int64_t i = 0; i < n; ++i) {
    zip_stat_t st;
    if (zip_stat_index(archive.get(), zip_uint64_t(i), 0, &st) != 0 || !(st.valid & ZIP_STAT_NAME))
      return bad_zip("zip entry " + std::to_string(i) + " cannot be read");
    std::string name = st.name;
    if (!name.empty() && name.back() == '/') continue;  // a directory entry: made on demand
    if (auto why = unsafe_relative_path(name); !why.empty()) return bad_zip("zip entry " + why);
    zip_uint8_t os = 0;
    zip_uint32_t attributes = 0;
    if (zip_file_get_external_attributes(archive.get(), zip_uint64_t(i), 0, &os, &attributes) == 0 &&
        os == ZIP_OPSYS_UNIX && S_ISLNK(attributes >> 16))
      return bad_zip("zip entry '" + name.substr(0, 80) + "' is a symbolic link");
    if ((st.valid & ZIP_STAT_SIZE) && (st.valid & ZIP_STAT_COMP_SIZE) && st.size > 4096 &&
        st.size / std::max<zip_uint64_t>(st.comp_size, 1) > kMaxZipRatio)
      return {{413, "too-large", "zip entry '" + name.substr(0, 80) + "' expands more than " +
                                     std::to_string(kMaxZipRatio) + "x (refused as a zip bomb)"}};
    std::unique_ptr<zip_file_t, ZipFileCloser> in(zip_fopen_index(archive.get(), zip_uint64_t(i), 0));
    if (!in) return bad_zip("zip entry '" + name.substr(0, 80) + "' cannot be opened (encrypted or unsupported)");
    const fs::path out_path = dest / name;
    fs::create_directories(out_path.parent_path());
    if (fs::exists(out_path)) return bad_zip("zip entry '" + name.substr(0, 80) + "' appears twice");
    std::ofstream out(out_path, std::ios::binary);
    if (!out) return {{500, "internal", "an unpacked file cannot be written"}};
    for (;;) {
      const zip_int64_t got = zip_fread(in.get(), buf.data(), buf.size());
      if (got < 0) return bad_zip("zip entry '" + name.substr(0, 80) + "' is corrupt");
      if (got == 0) break;
      total += uint64_t(got);
      if (total > budget) return {{413, "too-large", "the zip unpacks to more than the upload byte limit"}};
      out.write(buf.data(), got);
    }
    if (!out.flush()) return {{500, "internal", "an unpacked file cannot be written"}};
    if (is_model_name(name)) {
      const size_t depth = size_t(std::count(name.begin(), name.end(), '/'));
      if (depth < best_depth) {
        best_depth = depth;
        at_best = 0;
        model = name;
      }
      if (depth == best_depth) ++at_best;
    }
  }
  if (model.empty()) return bad_zip("the zip holds no .gltf or .glb");
  if (at_best > 1) return bad_zip("the zip holds several models at the top level; send one per job");
  return std::nullopt;
}

}  // namespace soupuv::server
