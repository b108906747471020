// Names of enumeration values, the one home of the small name tables (an enum's value <-> its
// name in files, options and messages) that modules and front ends wrote as switch statements
// and if-chains: a table of (value, name) pairs, looked up both ways.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace vs {

template <class E, size_t N>
using NameTable = std::pair<E, const char*>[N];

// The name of `value` in `table`, or `other` when the table does not list it.
template <class E, size_t N>
std::string nameOf(const NameTable<E, N>& table, E value, const char* other = "?") {
  for (const auto& [v, name] : table)
    if (v == value) return name;
  return other;
}

// The value named `name`, or nothing.
template <class E, size_t N>
std::optional<E> valueOf(const NameTable<E, N>& table, const std::string& name) {
  for (const auto& [v, n] : table)
    if (name == n) return v;
  return std::nullopt;
}

// The names in table order, joined by `separator` ("livewire, trace, surface").
template <class E, size_t N>
std::string namesText(const NameTable<E, N>& table, const char* separator = ", ") {
  std::string s;
  for (const auto& entry : table) s += (s.empty() ? "" : separator) + std::string(entry.second);
  return s;
}

}  // namespace vs
