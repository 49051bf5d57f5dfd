// The RSS's construction, merging and checks, compiled once (volumes/CMakeLists.txt).
#include "rss.hpp"

#include "principal_axes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace bvhlab {

Rss Rss::fit(std::span<const Vec3> points) {
  if (std::any_of(points.begin(), points.end(), [](const Vec3& p) { return !p.allFinite(); }))
    throw std::invalid_argument("rss::fit: a point has a NaN or infinite coordinate");
  return fit_balls(points, {});
}

Rss Rss::merge(const Rss& a, const Rss& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  std::array<Vec3, 8> corners;
  a.write_corners(corners.data());
  b.write_corners(corners.data() + 4);
  std::array<double, 8> radii;
  std::fill(radii.begin(), radii.begin() + 4, a.corner_radius());
  std::fill(radii.begin() + 4, radii.end(), b.corner_radius());
  return fit_balls(corners, radii);
}

bool Rss::valid() const {
  double norm2 = 0;
  for (float q : orientation) {
    if (!std::isfinite(q)) return false;
    norm2 += double(q) * q;
  }
  for (float c : center)
    if (!std::isfinite(c)) return false;
  for (float h : half)
    if (!(std::isfinite(h) && h >= 0)) return false;
  return std::isfinite(radius) && radius >= 0 && norm2 > 0.5 && norm2 < 2;
}

bool Rss::contains(const Vec3& p) const {
  if (empty()) return false;
  return distance_to_rectangle(Obb::axes_of(orientation), to_vec(center), half[0], half[1], p) <= radius;
}

void Rss::write_corners(Vec3* out) const {
  const Mat3 axes = Obb::axes_of(orientation);
  const Vec3 c = to_vec(center), u = double(half[0]) * axes.col(0), v = double(half[1]) * axes.col(1);
  out[0] = c - u - v;
  out[1] = c + u - v;
  out[2] = c + u + v;
  out[3] = c - u + v;
}

double Rss::corner_radius() const {
  const Vec3 c = to_vec(center);
  return double(radius) + kFrameRounding * std::hypot(double(half[0]), double(half[1])) + 0x1p-24 * c.norm() +
         16 * kEps * magnitude();
}

double Rss::distance_to_rectangle(const Mat3& axes, const Vec3& center, double h0, double h1, const Vec3& p) {
  const Vec3 local = axes.transpose() * (p - center);
  return std::sqrt(rss::detail::outside_squared(local.x(), h0) + rss::detail::outside_squared(local.y(), h1) +
                   local.z() * local.z());
}

Rss Rss::fit_balls(std::span<const Vec3> points, std::span<const double> radii) {
  if (points.empty()) return {};
  const Vec3 mean = mean_point(points);
  const Rss by_pca = fit_in_frame(points, radii, mean, principal_axes(points, mean));
  const Rss by_axes = fit_in_frame(points, radii, mean, Mat3::Identity());
  return smaller(by_pca, by_axes) ? by_pca : by_axes;
}

Rss Rss::fit_in_frame(std::span<const Vec3> points, std::span<const double> radii, const Vec3& origin,
                      const Mat3& frame) {
  const auto radius_of = [&](std::size_t i) { return radii.empty() ? 0.0 : radii[i]; };
  // The normal: the axis along which the balls are thinnest.
  Vec3 lo = Vec3::Constant(rss::detail::kInfinity), hi = -lo;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 s = frame.transpose() * (points[i] - origin);
    lo = lo.cwiseMin(s - Vec3::Constant(radius_of(i)));
    hi = hi.cwiseMax(s + Vec3::Constant(radius_of(i)));
  }
  int normal = 0;
  (hi - lo).minCoeff(&normal);
  Mat3 axes;
  axes.col(0) = frame.col((normal + 1) % 3);
  axes.col(1) = frame.col((normal + 2) % 3);
  axes.col(2) = axes.col(0).cross(axes.col(1));  // right-handed, so it is a rotation
  const Mat3 to_local = axes.transpose();

  // The slab: the radius spans the balls along the normal.
  double z_lo = rss::detail::kInfinity, z_hi = -z_lo;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double z = axes.col(2).dot(points[i] - origin);
    z_lo = std::min(z_lo, z - radius_of(i));
    z_hi = std::max(z_hi, z + radius_of(i));
  }
  const double z_mid = (z_lo + z_hi) / 2, slab = (z_hi - z_lo) / 2;
  // How far a ball's centre may lie beyond the rectangle, in its plane, for the ball to stay in the volume.
  const auto allowance = [&](double z, double r) {
    return std::sqrt(std::max(0.0, rss::detail::square(slab - r) - rss::detail::square(z - z_mid)));
  };

  // The rectangle: on each axis the smallest interval no centre exceeds by more than its allowance.
  double side_lo[2], side_hi[2];
  {
    double lowest_high[2] = {rss::detail::kInfinity, rss::detail::kInfinity};    // min of x + allowance
    double highest_low[2] = {-rss::detail::kInfinity, -rss::detail::kInfinity};  // max of x - allowance
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3 s = to_local * (points[i] - origin);
      const double a = allowance(s.z(), radius_of(i));
      for (int k = 0; k < 2; ++k) {
        lowest_high[k] = std::min(lowest_high[k], s[k] + a);
        highest_low[k] = std::max(highest_low[k], s[k] - a);
      }
    }
    for (int k = 0; k < 2; ++k) {
      if (lowest_high[k] <= highest_low[k]) {
        side_lo[k] = lowest_high[k];
        side_hi[k] = highest_low[k];
      } else {  // any point between will do: no extent
        side_lo[k] = side_hi[k] = (lowest_high[k] + highest_low[k]) / 2;
      }
    }
  }
  // A centre beyond a corner needs its distance to the corner, not only each axis's, within its allowance:
  // push out the side whose move adds less volume.
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 s = to_local * (points[i] - origin);
    const double a = allowance(s.z(), radius_of(i));
    const double dx = std::max({0.0, side_lo[0] - s.x(), s.x() - side_hi[0]});
    const double dy = std::max({0.0, side_lo[1] - s.y(), s.y() - side_hi[1]});
    if (dx == 0 || dy == 0 || dx * dx + dy * dy <= a * a) continue;
    const double keep_x = std::sqrt(std::max(0.0, a * a - dy * dy));  // what x may exceed by, y unchanged
    const double keep_y = std::sqrt(std::max(0.0, a * a - dx * dx));
    // Volume added per unit of a side's move: slab height times the other side, and the rounded edge.
    const double cost_x =
        (dx - keep_x) * (4 * slab * (side_hi[1] - side_lo[1]) + std::numbers::pi * slab * slab);
    const double cost_y =
        (dy - keep_y) * (4 * slab * (side_hi[0] - side_lo[0]) + std::numbers::pi * slab * slab);
    const int k = cost_x <= cost_y ? 0 : 1;
    const double keep = k == 0 ? keep_x : keep_y;
    if (s[k] < side_lo[k])
      side_lo[k] = s[k] + keep;
    else
      side_hi[k] = s[k] - keep;
  }

  // The radius, measured as contains() measures it.
  const Vec3 center =
      origin + axes * Vec3((side_lo[0] + side_hi[0]) / 2, (side_lo[1] + side_hi[1]) / 2, z_mid);
  const double h0 = (side_hi[0] - side_lo[0]) / 2, h1 = (side_hi[1] - side_lo[1]) / 2;
  double reach = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    reach = std::max(reach, distance_to_rectangle(axes, center, h0, h1, points[i]) + radius_of(i));
  return rounded(axes, center, h0, h1, reach);
}

Rss Rss::rounded(const Mat3& axes, const Vec3& center, double h0, double h1, double reach) {
  Rss out;
  Eigen::Quaterniond q(axes);
  q.normalize();
  out.orientation = {float(q.x()), float(q.y()), float(q.z()), float(q.w())};
  out.center = {float(center.x()), float(center.y()), float(center.z())};
  out.half = {float_up(h0), float_up(h1)};
  const double moved = kFrameRounding * std::hypot(double(out.half[0]), double(out.half[1])) +
                       0x1p-24 * center.norm() + 32 * kEps * (h0 + h1 + reach) + 1e-44;
  out.radius = float_up((reach + moved) * (1 + 8 * kEps));
  return out;
}

bool Rss::smaller(const Rss& a, const Rss& b) {
  const double va = a.volume(), vb = b.volume();
  if (std::abs(va - vb) > 1e-9 * std::max(va, vb)) return va < vb;
  const double aa = double(a.half[0]) * a.half[1], ab = double(b.half[0]) * b.half[1];
  if (std::abs(aa - ab) > 1e-9 * std::max(aa, ab)) return aa < ab;
  return double(a.half[0]) + a.half[1] + a.radius <= double(b.half[0]) + b.half[1] + b.radius;
}

}  // namespace bvhlab
