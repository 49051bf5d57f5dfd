// The principal axes and the mean of a point set (principal_axes.hpp).
#include "principal_axes.hpp"

#include <Eigen/Eigenvalues>

namespace bvhlab {

Vec3 mean_point(std::span<const Vec3> points) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p;
  return mean / double(points.size());
}

Mat3 principal_axes(std::span<const Vec3> points, const Vec3& mean) {
  Mat3 covariance = Mat3::Zero();
  for (const Vec3& p : points) covariance += (p - mean) * (p - mean).transpose();
  Mat3 axes = Mat3::Identity();
  if (!covariance.allFinite()) return axes;
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
  if (solver.info() != Eigen::Success) return axes;
  axes = solver.eigenvectors();
  axes.col(2) = axes.col(0).cross(axes.col(1));  // right-handed, so it is a rotation
  return axes;
}

}  // namespace bvhlab
