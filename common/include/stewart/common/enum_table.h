#pragma once
// One table per enum: the names a user types (config, command line, report)
// and the values they mean, in one place. Every parser, printer and --help
// reads the table, so a new value cannot be forgotten in one of them.
//
//   inline constexpr EnumTable<Color, 2> kColorNames{{{
//       {Color::kRed, "red"}, {Color::kBlue, "blue"}}}};
//   kColorNames.Name(Color::kRed)          -> "red"
//   kColorNames.Parse("blue", "--color")   -> Color::kBlue, or InputError
//   kColorNames.Names()                    -> "red | blue"
//   std::array<long, kColorNames.size()>   -> one counter per value
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "stewart/common/check.h"

namespace stewart {

template <typename Enum, std::size_t N>
struct EnumTable {
  std::array<std::pair<Enum, std::string_view>, N> entries;

  static constexpr std::size_t size() { return N; }

  /// The name of `value`; "?" for a value outside the table (a cast int).
  constexpr std::string_view Name(Enum value) const {
    for (const auto& [v, name] : entries) {
      if (v == value) return name;
    }
    return "?";
  }

  /// The position of `value` in the table (for per-value counters); N when absent.
  constexpr std::size_t Index(Enum value) const {
    for (std::size_t i = 0; i < N; ++i) {
      if (entries[i].first == value) return i;
    }
    return N;
  }

  constexpr std::optional<Enum> Find(std::string_view name) const {
    for (const auto& [v, n] : entries) {
      if (n == name) return v;
    }
    return std::nullopt;
  }

  /// The value named `name`; throws InputError naming `key` and the choices.
  Enum Parse(std::string_view name, const std::string& key) const {
    if (const std::optional<Enum> v = Find(name)) return *v;
    throw InputError(key, "'" + std::string(name) + "' is not one of " + Names());
  }

  /// Every name, in table order.
  std::vector<std::string> NameList() const {
    std::vector<std::string> names;
    names.reserve(N);
    for (const auto& entry : entries) names.emplace_back(entry.second);
    return names;
  }

  /// "a | b | c", for --help and error messages.
  std::string Names(std::string_view separator = " | ") const {
    std::string joined;
    for (std::size_t i = 0; i < N; ++i) {
      if (i > 0) joined += separator;
      joined += entries[i].second;
    }
    return joined;
  }
};

}  // namespace stewart
