// Value checks of the CLI's flag table (see value_check.h).
#include "value_check.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace soupuv::cli {

namespace {

bool is_word(const ValueCheck& c, const std::string& value) {
  for (const std::string& w : c.words)
    if (value == w) return true;
  return false;
}

std::string join_words(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : "|") + w;
  return out;
}

// Shortest text that reads back as x (17 digits would print 0.1 as 0.10000000000000001).
std::string number_text(double x) {
  std::ostringstream s;
  s.precision(15);
  s << x;
  return s.str();
}

std::string interval(const ValueCheck& c) {
  const bool low = std::isfinite(c.lo), high = std::isfinite(c.hi);
  std::string out;  // appended piece by piece (GCC 12 misreads a chain of + here: -Wrestrict)
  if (low && high) {
    out += c.lo_open ? "(" : "[";
    out += number_text(c.lo);
    out += ", ";
    out += number_text(c.hi);
    out += c.hi_open ? ")" : "]";
  } else if (low) {
    out += c.lo_open ? "> " : ">= ";
    out += number_text(c.lo);
  } else if (high) {
    out += c.hi_open ? "< " : "<= ";
    out += number_text(c.hi);
  }
  return out;
}

// " in (0, 1)", " >= 0" or "" (no bounds), to follow "a number".
std::string in_interval(const ValueCheck& c) {
  const std::string range = interval(c);
  if (range.empty()) return "";
  return (range[0] == '(' || range[0] == '[' ? " in " : " ") + range;
}

}  // namespace

double parse_number(const std::string& text) {
  size_t used = 0;
  const double x = std::stod(text, &used);  // throws std::invalid_argument / out_of_range
  if (used != text.size() || !std::isfinite(x)) throw std::invalid_argument(text);
  return x;
}

std::string ValueCheck::check(const std::string& value) const {
  if (is_word(*this, value)) return "";
  if (kind == Kind::text) {
    if (words.empty()) return "";
    return "must be " + join_words(words) + ", not '" + value + "'";
  }
  const std::string what = kind == Kind::integer ? "a whole number" : "a number";
  const std::string need = "needs " + (words.empty() ? what : join_words(words) + " or " + what) +
                           in_interval(*this) + ", not '" + value + "'";
  double x;
  try {
    x = parse_number(value);
  } catch (const std::exception&) {
    return need;
  }
  if (kind == Kind::integer && x != std::floor(x)) return need;
  if (lo_open ? !(x > lo) : !(x >= lo)) return need;
  if (hi_open ? !(x < hi) : !(x <= hi)) return need;
  return "";
}

std::string ValueCheck::describe() const {
  if (kind == Kind::text) return join_words(words);
  std::string range = interval(*this);
  if (range.empty()) range = kind == Kind::integer ? "whole number" : "number";
  return words.empty() ? range : join_words(words) + "|" + range;
}

nlohmann::json ValueCheck::to_json() const {
  nlohmann::json j = {{"type", kind == Kind::text ? "text" : kind == Kind::integer ? "integer" : "number"}};
  if (!words.empty()) j["words"] = words;
  if (kind != Kind::text) {
    if (std::isfinite(lo)) j[lo_open ? "above" : "min"] = lo;
    if (std::isfinite(hi)) j[hi_open ? "below" : "max"] = hi;
  }
  return j;
}

ValueCheck any_text() { return {}; }

ValueCheck one_of(std::vector<std::string> words) {
  ValueCheck c;
  c.words = std::move(words);
  return c;
}

ValueCheck number_in(double lo, double hi, bool lo_open, bool hi_open) {
  ValueCheck c;
  c.kind = ValueCheck::Kind::number;
  c.lo = lo;
  c.hi = hi;
  c.lo_open = lo_open;
  c.hi_open = hi_open;
  return c;
}

ValueCheck any_number() {
  ValueCheck c;
  c.kind = ValueCheck::Kind::number;
  return c;
}

ValueCheck whole_number_in(double lo, double hi) {
  ValueCheck c = number_in(lo, hi);
  c.kind = ValueCheck::Kind::integer;
  return c;
}

ValueCheck words_or(std::vector<std::string> words, ValueCheck number) {
  number.words = std::move(words);
  return number;
}

}  // namespace soupuv::cli
