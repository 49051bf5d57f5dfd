// The coherent queries' typed suite (coherent_suite.hpp) on the other half of the shipped volumes.
#include "coherent_suite.hpp"

namespace bvhlab::coherent_tests {
namespace {

using OddVolumes = testing::AlternateTypes<1, testing::TraversalTestVolumes>::type;
INSTANTIATE_TYPED_TEST_SUITE_P(OddVolumes, Coherent, OddVolumes);

}  // namespace
}  // namespace bvhlab::coherent_tests
