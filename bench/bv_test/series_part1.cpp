// The series of the registered volumes of odd index (bench/bv_test/series_impl.hpp).
#include "bench/bv_test/series_impl.hpp"

namespace bvhlab::bv_test {
template bool register_volume_part<1>(const std::string&, const std::string&,
                                      const std::shared_ptr<const Mesh>&, const std::vector<RigidTransform>&);
}  // namespace bvhlab::bv_test
