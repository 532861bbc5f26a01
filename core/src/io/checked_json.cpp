#include "io/checked_json.h"

#include <cmath>

#include "soupuv/errors.h"

namespace soupuv::io::detail {

void fail_input(const std::string& message) { throw Error(ErrorCode::invalid_input, message); }

uint64_t checked_add(uint64_t a, uint64_t b, std::string_view what) {
  uint64_t r;
  if (__builtin_add_overflow(a, b, &r)) fail_input(std::string(what) + ": size overflows 64 bits");
  return r;
}

uint64_t checked_mul(uint64_t a, uint64_t b, std::string_view what) {
  uint64_t r;
  if (__builtin_mul_overflow(a, b, &r)) fail_input(std::string(what) + ": size overflows 64 bits");
  return r;
}

const json* find_member(const json& obj, const char* key, std::string_view where) {
  if (!obj.is_object()) fail_input(std::string(where) + " is not a JSON object");
  auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

std::optional<uint64_t> get_opt_uint(const json& obj, const char* key, std::string_view where) {
  const json* v = find_member(obj, key, where);
  if (!v) return std::nullopt;
  if (v->is_number_unsigned()) return v->get<uint64_t>();
  // 2.0 and similar integral floats appear in hand-written files; accept them.
  if (v->is_number_float()) {
    double d = v->get<double>();
    if (d >= 0 && d <= 9.0e15 && std::floor(d) == d) return uint64_t(d);
  }
  fail_input(std::string(where) + "." + key + " is not a non-negative integer");
}

uint64_t get_uint(const json& obj, const char* key, std::string_view where) {
  auto v = get_opt_uint(obj, key, where);
  if (!v) fail_input(std::string(where) + " has no " + key);
  return *v;
}

bool get_opt_bool(const json& obj, const char* key, bool fallback, std::string_view where) {
  const json* v = find_member(obj, key, where);
  if (!v) return fallback;
  if (!v->is_boolean()) fail_input(std::string(where) + "." + key + " is not a boolean");
  return v->get<bool>();
}

std::optional<std::string> get_opt_string(const json& obj, const char* key, std::string_view where) {
  const json* v = find_member(obj, key, where);
  if (!v) return std::nullopt;
  if (!v->is_string()) fail_input(std::string(where) + "." + key + " is not a string");
  return v->get<std::string>();
}

std::optional<std::vector<double>> get_opt_numbers(const json& obj, const char* key, size_t n,
                                                   std::string_view where) {
  const json* v = find_member(obj, key, where);
  if (!v) return std::nullopt;
  if (!v->is_array() || v->size() != n)
    fail_input(std::string(where) + "." + key + " is not an array of " + std::to_string(n) + " numbers");
  std::vector<double> out;
  out.reserve(n);
  for (const json& x : *v) {
    if (!x.is_number()) fail_input(std::string(where) + "." + key + " holds a non-number");
    double d = x.get<double>();
    if (!std::isfinite(d)) fail_input(std::string(where) + "." + key + " holds a non-finite number");
    out.push_back(d);
  }
  return out;
}

size_t array_size(const json& doc, const char* array) {
  const json* a = find_member(doc, array, "glTF document");
  if (!a) return 0;
  if (!a->is_array()) fail_input(std::string("glTF '") + array + "' is not an array");
  return a->size();
}

const json& element(const json& doc, const char* array, uint64_t index, std::string_view where) {
  size_t n = array_size(doc, array);
  if (index >= n)
    fail_input(std::string(where) + " refers to " + array + "[" + std::to_string(index) +
               "] but there are " + std::to_string(n));
  const json& e = doc[array][size_t(index)];
  if (!e.is_object()) fail_input(std::string(array) + "[" + std::to_string(index) + "] is not an object");
  return e;
}

}  // namespace soupuv::io::detail
