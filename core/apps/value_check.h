// What value a CLI flag accepts — a number or whole number in a range, one of
// some words, or a number beside words (--offset auto|F) — in one description
// that the flag table turns into the CLI11 validator, the help text and
// `soupuv capabilities --json`, so the three cannot disagree.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace soupuv::cli {

struct ValueCheck {
  enum class Kind { text, number, integer };
  Kind kind = Kind::text;
  // For number and integer: the interval, each end closed unless marked open.
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  // Words accepted as they are: the whole choice for text, else beside the number.
  std::vector<std::string> words;

  // "" when `value` is accepted, else why not (one line).
  std::string check(const std::string& value) const;
  // "(0, 1)", "[1, 100000]", "euler|midpoint", "auto|(0, 1)"; "" for free text.
  std::string describe() const;
  nlohmann::json to_json() const;
};

ValueCheck any_text();
ValueCheck one_of(std::vector<std::string> words);
// A finite number in the interval; open ends are marked with the flags.
ValueCheck number_in(double lo, double hi, bool lo_open = false, bool hi_open = false);
ValueCheck any_number();
ValueCheck whole_number_in(double lo, double hi);
// `words` or a number in the interval (e.g. auto or a fraction in (0, 1)).
ValueCheck words_or(std::vector<std::string> words, ValueCheck number);

// The whole text as a finite number; throws std::invalid_argument otherwise
// (no trailing characters, no nan or inf).
double parse_number(const std::string& text);

}  // namespace soupuv::cli
