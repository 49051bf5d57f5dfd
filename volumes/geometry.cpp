// Checks of caller input on the geometric vocabulary (geometry.hpp), compiled once.
#include "geometry.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bvhlab {

namespace {

/// Whether `t` passes validate's checks with room to spare: one pass without branches, as every query
/// runs it. Its sums round differently from the checks themselves, so a pose it does not pass goes through
/// them (they decide, and name the defect).
bool plainly_rigid(const RigidTransform& t, Scalar tolerance) {
  const Mat3& r = t.rotation;
  // 0 when the translation is finite (and its sum does not overflow), else NaN. A rotation entry that is
  // not finite makes a column's squared length NaN or infinite, which fails the comparison below.
  const Scalar finite = (t.translation.x() + t.translation.y() + t.translation.z()) * 0;
  const auto dot = [&r](int i, int j) { return r(0, i) * r(0, j) + r(1, i) * r(1, j) + r(2, i) * r(2, j); };
  const Scalar orthogonality =
      std::max({std::abs(dot(0, 1)), std::abs(dot(0, 2)), std::abs(dot(1, 2)), std::abs(dot(0, 0) - 1),
                std::abs(dot(1, 1) - 1), std::abs(dot(2, 2) - 1)});
  const Scalar det = r(0, 0) * (r(1, 1) * r(2, 2) - r(2, 1) * r(1, 2)) -
                     r(1, 0) * (r(0, 1) * r(2, 2) - r(2, 1) * r(0, 2)) +
                     r(2, 0) * (r(0, 1) * r(1, 2) - r(1, 1) * r(0, 2));
  return finite == 0 && orthogonality <= tolerance / 2 && det > 0;
}

/// validate's checks, one by one: throws naming the first that fails. Apart from the plain pass, whose
/// registers its message building would otherwise crowd.
[[gnu::noinline, gnu::cold]] void check_each(const Mat3& rotation, const Vec3& translation,
                                             Scalar tolerance) {
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

}  // namespace

void RigidTransform::validate(Scalar tolerance) const {
  if (!plainly_rigid(*this, tolerance)) check_each(rotation, translation, tolerance);
}

}  // namespace bvhlab
