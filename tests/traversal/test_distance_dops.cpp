// The proximity queries' typed tests (distance_query_tests.hpp) on the other volumes with a distance bound:
// compiled apart from test_distance.cpp's, so that each unit compiles half of the volumes' queries.
#include "distance_query_tests.hpp"

namespace bvhlab::distance_tests {
namespace {

// The sanitizer builds keep the lean volume list, as tests/support/volume_lists.hpp explains.
#ifdef BVHLAB_LEAN_VOLUMES
using OtherDistanceVolumes = ::testing::Types<Dop24>;
#else
using OtherDistanceVolumes = ::testing::Types<Rss, Dop<6>, Dop<14>, Dop24>;
#endif
INSTANTIATE_TYPED_TEST_SUITE_P(Others, DistanceQuery, OtherDistanceVolumes);

}  // namespace
}  // namespace bvhlab::distance_tests
