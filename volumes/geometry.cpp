// Checks of caller input on the geometric vocabulary (geometry.hpp), compiled once.
#include "geometry.hpp"

#include <stdexcept>
#include <string>

namespace bvhlab {

void RigidTransform::validate(Scalar tolerance) const {
  if (!rotation.allFinite()) throw std::invalid_argument("transform: rotation has a NaN or infinite entry");
  if (!translation.allFinite())
    throw std::invalid_argument("transform: translation has a NaN or infinite entry");
  const Scalar orthogonality = (rotation.transpose() * rotation - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(orthogonality <= tolerance))
    throw std::invalid_argument(
        "transform: rotation is not orthonormal (max |R^T R - I| = " + std::to_string(orthogonality) + ")");
  if (rotation.determinant() < 0)
    throw std::invalid_argument("transform: rotation is a reflection (det R = -1), not a rigid motion");
}

}  // namespace bvhlab
