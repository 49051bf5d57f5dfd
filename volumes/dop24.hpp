// Zachmann's DOP-tree volume: a 24-DOP (12 axes), re-aligned under rotation as described in kdop.hpp.
//
// The 12 axes: x, y, z; the six edge diagonals (1, +-1, 0), (1, 0, +-1), (0, 1, +-1); and three of the four
// corner diagonals, (1, 1, -1), (1, -1, 1), (-1, 1, 1). That is the 18-DOP with three corners cut, a set
// used for 24-DOPs in practice; the paper does not pin it down here, so the choice is ours (the fourth
// corner diagonal would make it the 26-DOP). The axes double as the builder's split directions, as in the
// DOP-tree.
#pragma once

#include "kdop.hpp"

namespace bvhlab {

namespace dop_sets {
struct Zachmann24 {
  static constexpr std::string_view name = "dop24";
  static constexpr bool split_along_directions = true;
  static constexpr dop_detail::DirectionSet<12> set{{{{1, 0, 0},
                                                      {0, 1, 0},
                                                      {0, 0, 1},
                                                      {1, 1, 0},
                                                      {1, -1, 0},
                                                      {1, 0, 1},
                                                      {1, 0, -1},
                                                      {0, 1, 1},
                                                      {0, 1, -1},
                                                      {1, 1, -1},
                                                      {1, -1, 1},
                                                      {-1, 1, 1}}}};
};
}  // namespace dop_sets

using Dop24 = KDop<dop_sets::Zachmann24>;

static_assert(BoundingVolume<Dop24> && DistanceVolume<Dop24>);

}  // namespace bvhlab
