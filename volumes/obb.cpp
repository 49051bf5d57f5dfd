// The OBB's construction, merging and checks, compiled once (volumes/CMakeLists.txt).
#include "obb.hpp"

#include "principal_axes.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace bvhlab {

Obb Obb::merge(const Obb& a, const Obb& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  std::array<Vec3, 16> corners;
  a.write_corners(corners.data());
  b.write_corners(corners.data() + 8);
  // Corners are computed in double; widen by their rounding, and by the float rounding of the inputs'
  // frames and centres (which the GCC 12 folding may undo when they were just stored, see box_in_frame).
  const double magnitude = std::max(a.magnitude(), b.magnitude());
  return fit_with_margin(corners, (kFrameRounding + 16 * std::numeric_limits<double>::epsilon()) * magnitude);
}

Obb Obb::fit_in_frame_of(const Obb& previous, std::span<const TrianglePoints> triangles) {
  if (triangles.empty()) return {};
  const Mat3 axes = axes_of(previous.orientation);
  const Mat3 to_local = axes.transpose();
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  double reach = 0;  // largest |coordinate| of a point
  for (const TrianglePoints& t : triangles)
    for (const Vec3& p : t) {
      if (!p.allFinite()) throw std::invalid_argument("obb::fit: a point has a NaN or infinite coordinate");
      const Vec3 s = to_local * p;
      lo = lo.cwiseMin(s);
      hi = hi.cwiseMax(s);
      reach = std::max(reach, p.cwiseAbs().maxCoeff());
    }
  Obb out;
  out.orientation = previous.orientation;  // the frame is exactly axes_of(orientation): no frame rounding
  const Vec3 center = axes * ((lo + hi) * 0.5);
  out.center = {float(center.x()), float(center.y()), float(center.z())};
  // Storing the centre as float moves it by up to 2^-24 |c|; contains() measures p - c in the frame, which
  // differs from the projections above by a few roundings of |p| and |c| (32 ulps is generous).
  const double magnitude = reach + center.cwiseAbs().maxCoeff();
  const double widen =
      0x1p-24 * center.norm() + 32 * std::numeric_limits<double>::epsilon() * magnitude + 1e-44;
  out.half =
      float3_up(Vec3((((hi - lo) * 0.5).array() + widen) * (1 + 8 * std::numeric_limits<double>::epsilon())));
  return out;
}

bool Obb::valid() const {
  double norm2 = 0;
  for (float q : orientation) {
    if (!std::isfinite(q)) return false;
    norm2 += double(q) * q;
  }
  for (int k = 0; k < 3; ++k)
    if (!(std::isfinite(center[k]) && std::isfinite(half[k]) && half[k] >= 0)) return false;
  return norm2 > 0.5 && norm2 < 2;
}

bool Obb::contains(const Vec3& p) const {
  if (empty()) return false;
  const Vec3 local = local_coordinates(axes_of(orientation), to_vec(center), p);
  return (local.cwiseAbs().array() <= to_vec(half).array()).all();
}

Vec3 Obb::local_coordinates(const Mat3& axes, const Vec3& center, const Vec3& p) {
  return axes.transpose() * (p - center);
}

void Obb::write_corners(Vec3* out) const {
  const Mat3 axes = axes_of(orientation);
  const Vec3 c = to_vec(center), h = to_vec(half);
  for (int k = 0; k < 8; ++k)
    out[k] = c + axes * Vec3(k & 1 ? h[0] : -h[0], k & 2 ? h[1] : -h[1], k & 4 ? h[2] : -h[2]);
}

Obb Obb::box_in_frame(std::span<const Vec3> points, const Mat3& frame, double margin) {
  Obb out;
  Eigen::Quaterniond q(frame);
  q.normalize();
  out.orientation = {float(q.x()), float(q.y()), float(q.z()), float(q.w())};
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : points) {
    const Vec3 s = frame.transpose() * p;
    lo = lo.cwiseMin(s);
    hi = hi.cwiseMax(s);
  }
  const Vec3 center = frame * ((lo + hi) * 0.5);
  out.center = {float(center.x()), float(center.y()), float(center.z())};
  Vec3 reach = Vec3::Zero();
  double farthest = 0;
  for (const Vec3& p : points) {
    reach = reach.cwiseMax(local_coordinates(frame, center, p).cwiseAbs());
    farthest = std::max(farthest, (p - center).norm());
  }
  const double widen = kFrameRounding * farthest + 0x1p-24 * center.norm() + 1e-44 + margin;
  out.half = float3_up((reach.array() + widen) * (1 + 8 * std::numeric_limits<double>::epsilon()));
  return out;
}

Obb Obb::fit_with_margin(std::span<const Vec3> points, double margin) {
  if (std::any_of(points.begin(), points.end(), [](const Vec3& p) { return !p.allFinite(); }))
    throw std::invalid_argument("obb::fit: a point has a NaN or infinite coordinate");
  if (points.empty()) return {};
  const Mat3 pca = principal_axes(points, mean_point(points));
  const Obb by_pca = box_in_frame(points, pca, margin);
  const Obb by_axes = box_in_frame(points, Mat3::Identity(), margin);
  return smaller(by_pca, by_axes) ? by_pca : by_axes;
}

bool Obb::smaller(const Obb& a, const Obb& b) {
  const Vec3 ha = to_vec(a.half), hb = to_vec(b.half);
  auto area = [](const Vec3& h) { return h[0] * h[1] + h[1] * h[2] + h[0] * h[2]; };
  const double va = a.volume(), vb = b.volume();
  if (std::abs(va - vb) > 1e-9 * std::max(va, vb)) return va < vb;
  const double aa = area(ha), ab = area(hb);
  if (std::abs(aa - ab) > 1e-9 * std::max(aa, ab)) return aa < ab;
  return ha.sum() <= hb.sum();
}

}  // namespace bvhlab
