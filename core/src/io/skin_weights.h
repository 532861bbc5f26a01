// Skin weights that glTF accepts. The spec wants each vertex's weights (over
// all its WEIGHTS_n sets) to sum to 1, and the Khronos validator refuses a
// file where the float32 sum is off by more than 2e-7 per non-zero weight.
// Some real assets break this (CesiumMan: 210 vertices off by up to 0.8);
// renderers normalize such weights when they load them (three.js does), so
// the writer does the same for those vertices and keeps every other vertex's
// weights bit for bit.
#pragma once

#include <array>
#include <span>

namespace soupuv::io::detail {

// The validator's test: the float32 sum, component by component across the
// sets (its order), within 2e-7 of 1 per non-zero weight.
bool weights_pass_validator(std::span<const std::array<float, 4>> sets);

// One vertex's weights, set by set. Returns false (untouched) when they are
// already normalized as the validator sums them, or when they cannot be
// (non-finite, negative, or all zero); otherwise scales them to sum to 1 in
// float32 and returns true.
bool normalize_skin_weights(std::span<std::array<float, 4>> sets);

}  // namespace soupuv::io::detail
