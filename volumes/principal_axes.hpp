// The frame the oriented volumes fit in: the principal axes of a point set (the eigenvectors of its
// covariance), shared by the OBB's and the RSS's fit.
#pragma once

#include "geometry.hpp"

#include <span>

namespace bvhlab {

/// The mean of `points` (not empty).
Vec3 mean_point(std::span<const Vec3> points);

/// The eigenvectors of the covariance of `points` about `mean`, as the columns of a rotation (right-handed);
/// the identity when the covariance is not finite or the solver fails.
Mat3 principal_axes(std::span<const Vec3> points, const Vec3& mean);

}  // namespace bvhlab
