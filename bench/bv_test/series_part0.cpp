// The series of the registered volumes of even index (bench/bv_test/series_impl.hpp).
#include "bench/bv_test/series_impl.hpp"

namespace bvhlab::bv_test {
template bool register_volume_part<0>(const std::string&, const std::string&,
                                      const std::shared_ptr<const Mesh>&, const std::vector<RigidTransform>&);
}  // namespace bvhlab::bv_test
