#include "adb/parameters.hpp"

#include <cstdio>
#include <cstdlib>

namespace bvhlab {

std::string parameter_text(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", value);
  if (std::strtod(buf, nullptr) != value) std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

std::string ParamSpec::range_text() const {
  std::string out = integer ? "an integer in " : "";
  out += exclusive_min ? '(' : '[';
  out += parameter_text(min);
  out += ", ";
  out += parameter_text(max);
  out += ']';
  return out;
}

std::string ParamSpec::problem(double value) const {
  // -0 lies below a range that starts at 0: one value, one encoding (saved trees must save back identically).
  const bool below =
      exclusive_min ? !(value > min) : !(value >= min) || (min == 0 && value == 0 && std::signbit(value));
  if (!std::isfinite(value) || below || !(value <= max) || (integer && value != std::floor(value)))
    return "must be " + std::string(integer ? "" : "a number in ") + range_text() + ", got " +
           parameter_text(value);
  return {};
}

ParamValues resolve_parameters(std::span<const ParamSpec> specs, const ParamValues& given,
                               std::string_view owner) {
  auto fail = [&](const std::string& problem) {
    throw std::invalid_argument(std::string(owner) + ": " + problem);
  };
  for (const auto& [name, value] : given) {
    bool known = false;
    for (const ParamSpec& spec : specs) known = known || spec.name == name;
    if (!known) {
      std::string names;
      for (const ParamSpec& spec : specs) names += (names.empty() ? "" : ", ") + std::string(spec.name);
      fail("unknown parameter '" + name + "' (" + (names.empty() ? "it takes none" : "it takes " + names) +
           ")");
    }
  }
  ParamValues out;
  for (const ParamSpec& spec : specs) {
    const auto it = given.find(spec.name);
    if (it == given.end() && spec.required()) fail("parameter '" + std::string(spec.name) + "' is required");
    const double value = it == given.end() ? spec.default_value : it->second;
    if (const std::string problem = spec.problem(value); !problem.empty())
      fail(std::string(spec.name) + " " + problem);
    out.emplace(std::string(spec.name), value);
  }
  return out;
}

double parameter(const ParamValues& values, std::string_view name) {
  const auto it = values.find(name);
  if (it == values.end()) throw std::invalid_argument("parameter '" + std::string(name) + "' is not set");
  return it->second;
}

}  // namespace bvhlab
