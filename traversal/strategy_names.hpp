// The names of the strategies that callers single out (FCL's models answer only exact and distance queries;
// the CLI's --all-contacts picks all_contacts, its --tolerance alone picks tolerance), apart from the
// strategies' templates: naming them then does not recompile a caller when a traversal changes.
#pragma once

#include <string_view>

namespace bvhlab {

inline constexpr std::string_view kExactStrategyName = "exact";
inline constexpr std::string_view kAllContactsStrategyName = "all_contacts";
inline constexpr std::string_view kDistanceStrategyName = "distance";
inline constexpr std::string_view kToleranceStrategyName = "tolerance";

}  // namespace bvhlab
