// The suite's per-volume helpers, instantiated once for every volume of BVHLAB_ROBUST_FOR_EACH_VOLUME
// (robust_support.hpp).
#include "robust_support.hpp"

namespace bvhlab::robust {

#define BVHLAB_ROBUST_DEFINE(BV) BVHLAB_ROBUST_INSTANTIATIONS(, BV)
BVHLAB_ROBUST_FOR_EACH_VOLUME(BVHLAB_ROBUST_DEFINE)

}  // namespace bvhlab::robust
