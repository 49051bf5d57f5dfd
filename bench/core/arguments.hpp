// Small helpers for the benchmarks' own command-line flags (comma-separated lists).
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace bvhlab {

/// "a,b,,c" -> {"a", "b", "c"}.
inline std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// "0.5,0.9" -> {0.5, 0.9}; throws std::invalid_argument for an item that is not a number.
inline std::vector<double> split_numbers(const std::string& s) {
  std::vector<double> out;
  for (const auto& item : split_list(s)) out.push_back(std::stod(item));
  return out;
}

}  // namespace bvhlab
