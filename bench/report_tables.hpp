// Small helpers the report writers and runners share: CSV files, nearest-rank quantiles and percentages.
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab::report_tables {

inline std::ofstream open_csv(const std::filesystem::path& file) {
  std::ofstream out(file, std::ios::trunc);
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
  return out;
}

/// The value below which `share` of `values` lie (nearest rank); 0 for none.
inline double quantile(std::vector<double> values, double share) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(share * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(rank, values.size() - 1)];
}

/// The median (the upper of the middle two for an even count: nearest rank); 0 for none.
inline double median(std::vector<double> values) {
  return quantile(std::move(values), 0.5);
}

/// part / whole in percent with two decimals, "-" for an empty whole.
inline std::string percent(std::size_t part, std::size_t whole) {
  return whole ? fmt::format("{:.2f}", 100.0 * static_cast<double>(part) / static_cast<double>(whole)) : "-";
}

}  // namespace bvhlab::report_tables
