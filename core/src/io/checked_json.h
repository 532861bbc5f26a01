// Checked access to the untrusted glTF JSON: every lookup verifies the type and
// range it expects and throws Error{invalid_input} naming the offending field,
// so the loader never trips over nlohmann's own exceptions or asserts.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace soupuv::io::detail {

using nlohmann::json;

[[noreturn]] void fail_input(const std::string& message);

// Overflow-safe 64-bit arithmetic: throws invalid_input naming `what`.
uint64_t checked_add(uint64_t a, uint64_t b, std::string_view what);
uint64_t checked_mul(uint64_t a, uint64_t b, std::string_view what);

// obj[key] when present, else nullptr. `obj` must be an object (checked).
const json* find_member(const json& obj, const char* key, std::string_view where);

// A required / optional non-negative integer member.
uint64_t get_uint(const json& obj, const char* key, std::string_view where);
std::optional<uint64_t> get_opt_uint(const json& obj, const char* key, std::string_view where);

bool get_opt_bool(const json& obj, const char* key, bool fallback, std::string_view where);
std::optional<std::string> get_opt_string(const json& obj, const char* key, std::string_view where);

// Exactly n finite numbers in an array member, or nullopt when absent.
std::optional<std::vector<double>> get_opt_numbers(const json& obj, const char* key, size_t n,
                                                   std::string_view where);

// doc[array][index] as an object; throws when the array or element is missing.
const json& element(const json& doc, const char* array, uint64_t index, std::string_view where);

// Size of doc[array] (0 when absent); throws when it is not an array.
size_t array_size(const json& doc, const char* array);

}  // namespace soupuv::io::detail
