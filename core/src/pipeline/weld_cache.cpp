#include "pipeline/weld_cache.h"


#include "soupuv/cache/bytes.h"
#include "soupuv/cache/store.h"

namespace soupuv::pipeline {

namespace {
// Bump when a weld's algorithm or this layout changes.
constexpr const char* kWeldCacheVersion = "weld-cache-2";  // 2: recipes as raw bytes
}  // namespace

std::string weld_recipe(const std::string& kind, std::initializer_list<double> parameters) {
  // Raw bytes, hashed as they are (never formatted).
  cache::ByteWriter w;
  w.put_string(kind);
  for (double p : parameters) w.put(p);
  const std::vector<uint8_t> bytes = w.take();
  return std::string(bytes.begin(), bytes.end());
}

geometry::Weld cached_weld(cache::Store* store, const std::string& soup_hash, const std::string& recipe,
                          const std::function<geometry::Weld()>& compute, bool& hit) {
  hit = false;
  if (!store) return compute();
  const std::string key = cache::cache_key({"weld", kWeldCacheVersion, soup_hash, recipe});
  if (auto bytes = store->get(key)) {
    cache::ByteReader rd(*bytes);
    geometry::Weld w;
    w.vertex_count = rd.get<uint32_t>();
    w.corner_vertex = rd.get_vector<uint32_t>();
    hit = true;
    return w;
  }
  geometry::Weld w = compute();
  cache::ByteWriter wr;
  wr.put<uint32_t>(w.vertex_count);
  wr.put_vector(w.corner_vertex);
  store->put(key, wr.take());
  return w;
}

}  // namespace soupuv::pipeline
