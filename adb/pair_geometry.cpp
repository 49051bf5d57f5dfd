#include "pair_geometry.hpp"

namespace bvhlab {

ReboxPose::ReboxPose(const RigidTransform& b_to_a)
    : rotation(b_to_a.rotation),
      translation(b_to_a.translation),
      abs_rotation(rotation.cwiseAbs()),
      inverse_rotation(rotation.transpose()),
      inverse_abs_rotation(abs_rotation.transpose()),
      inverse_translation(-(inverse_rotation * translation)) {}

}  // namespace bvhlab
