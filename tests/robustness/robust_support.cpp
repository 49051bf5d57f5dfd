// The suite's per-volume helpers, instantiated once for every shipped volume (robust_support.hpp).
#include "robust_support.hpp"

namespace bvhlab::robust {

#define BVHLAB_ROBUST_DEFINE(BV) BVHLAB_ROBUST_INSTANTIATIONS(, BV)
BVHLAB_ROBUST_DEFINE(Aabb)
BVHLAB_ROBUST_DEFINE(Dop<6>)
BVHLAB_ROBUST_DEFINE(Dop<14>)
BVHLAB_ROBUST_DEFINE(Dop<18>)
BVHLAB_ROBUST_DEFINE(Dop24)
BVHLAB_ROBUST_DEFINE(Dop<26>)
BVHLAB_ROBUST_DEFINE(Obb)
BVHLAB_ROBUST_DEFINE(Sphere)
BVHLAB_ROBUST_DEFINE(RestrictedBox)

}  // namespace bvhlab::robust
