// Byte encodings of the field branch's results for the cache. The version
// string goes into every cache key: bump it when a layout or an algorithm
// whose output is cached changes.
#pragma once

#include <span>
#include <string>

#include "soupuv/cache/store.h"
#include "soupuv/field/field.h"

namespace soupuv::pipeline {

inline constexpr const char* kFieldCacheVersion = "field-cache-10";  // 10: a stalled GMRES stops; 9: consistent seed weld, singular preconditioner blocks regularised; 8: no cut-probe switch

cache::Bytes encode(const field::ChargeResult& charges);
field::ChargeResult decode_charges(std::span<const uint8_t> bytes);

cache::Bytes encode(const field::FieldLines& lines);
field::FieldLines decode_lines(std::span<const uint8_t> bytes);

}  // namespace soupuv::pipeline
