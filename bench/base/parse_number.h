// Whole numbers in text, read one way everywhere: decimal digits only (no
// sign, spaces, hexadecimal or exponent), and nothing that does not fit the
// type. std::from_chars alone would take a leading "-"; strtoull wraps a
// minus and clamps an overflow to its largest value; stoul throws.
#pragma once

#include <charconv>
#include <concepts>
#include <optional>
#include <string_view>

namespace depthbench {

template <std::unsigned_integral T>
std::optional<T> ParseDigits(std::string_view text) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string_view::npos) return std::nullopt;
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;  // too large for T
  return value;
}

}  // namespace depthbench
