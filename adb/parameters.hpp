// Named numeric parameters of a policy (a density's grid and tau, a strategy's p_min), described by a table
// so that the scene parser, the CLI, reports and `bvhlab info` take names, ranges, defaults and help text
// from one place, and check values the same way before any work starts.
#pragma once

#include <cmath>
#include <limits>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace bvhlab {

/// One parameter a policy accepts.
struct ParamSpec {
  std::string_view name;
  std::string_view description;
  double min = 0, max = 0;  ///< closed range; `exclusive_min` makes the lower end open
  double default_value = std::numeric_limits<double>::quiet_NaN();  ///< NaN: the caller must give it
  bool integer = false;
  bool exclusive_min = false;
  /// A scene may give a list of values: each value is one variant of the policy (a p_min sweep).
  bool sweep = false;
  /// Printed in series labels ("adb p_min=0.9").
  bool in_label = false;
  /// With in_label: printed at its default value too. False for an option added later, so that the series
  /// that do not use it keep their labels ("adb p_min=0.9", not "adb p_min=0.9 confirm_levels=0").
  bool label_default = true;

  [[nodiscard]] bool required() const { return std::isnan(default_value); }
  /// "" when `value` is acceptable, else what is wrong with it ("must lie in [0, 1]").
  [[nodiscard]] std::string problem(double value) const;
  /// "[0, 1]", "(0, 1]", "an integer in [2, 4]".
  [[nodiscard]] std::string range_text() const;
};

/// Parameter values by name.
using ParamValues = std::map<std::string, double, std::less<>>;

/// `given` checked against `specs` and completed with defaults. Throws std::invalid_argument naming
/// `owner`, the parameter and the problem: an unknown name, a missing required value, a value out of range.
ParamValues resolve_parameters(std::span<const ParamSpec> specs, const ParamValues& given,
                               std::string_view owner);

/// The value of a resolved parameter; throws std::invalid_argument when absent.
double parameter(const ParamValues& values, std::string_view name);

/// "p_min=0.9 tau=0.25" in table order, for the parameters `include` selects.
template <class Include>
std::string describe_parameters(std::span<const ParamSpec> specs, const ParamValues& values,
                                Include&& include);

/// A number as reports print it: the shortest form that reads back ("0.25", "1e-06").
std::string parameter_text(double value);

template <class Include>
std::string describe_parameters(std::span<const ParamSpec> specs, const ParamValues& values,
                                Include&& include) {
  std::string out;
  for (const ParamSpec& spec : specs) {
    const auto it = values.find(spec.name);
    if (it == values.end() || !include(spec)) continue;
    // Appended in place: GCC 12 warns (-Wrestrict, falsely) on the temporaries of a concatenation here.
    if (!out.empty()) out.push_back(' ');
    out.append(spec.name).append("=").append(parameter_text(it->second));
  }
  return out;
}

}  // namespace bvhlab
