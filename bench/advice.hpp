// "The right tool, said out loud": where a scene or a query asks a strategy to work outside what it was made
// for, the words that say so and name the strategy made for the case, with the measured reason.
#pragma once

#include "bvh/mesh.hpp"

#include <string>
#include <string_view>

namespace bvhlab {

/// Objects whose root volumes differ by more than this are "of different size" for ADB.
inline constexpr double kSizeRatioForLarger = 10;

/// The ratio of the larger to the smaller bounding-box volume (each side at least 1e-3 of the box's longest,
/// so a flat object has a volume).
double root_volume_ratio(const Mesh& a, const Mesh& b);

/// For `strategy` on objects `a` and `b` (labelled `pair`): the advice, or "" when there is none.
std::string size_advice(std::string_view strategy, const std::string& pair, const Mesh& a, const Mesh& b);

}  // namespace bvhlab
