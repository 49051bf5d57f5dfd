// Basic geometric vocabulary shared by every layer: points, boxes, rigid transforms.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace bvhlab {

// Double precision throughout: the benchmark protocol normalises meshes to [-1, 1]^3, but the stiff-case
// suite translates them by up to 1e9, where float's 24-bit mantissa cannot even separate vertices.
using Scalar = double;
using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
using TrianglePoints = std::array<Vec3, 3>;

/// Axis-aligned box as plain data. An empty box has min > max on every axis.
struct Box {
  Vec3 min = Vec3::Constant(std::numeric_limits<Scalar>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<Scalar>::infinity());

  [[nodiscard]] bool empty() const { return (min.array() > max.array()).any(); }
  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void extend(const Box& b) {
    min = min.cwiseMin(b.min);
    max = max.cwiseMax(b.max);
  }
  [[nodiscard]] Vec3 center() const { return (min + max) * Scalar(0.5); }
  [[nodiscard]] Vec3 extent() const { return max - min; }
  [[nodiscard]] Scalar volume() const { return empty() ? Scalar(0) : extent().prod(); }
  [[nodiscard]] bool contains(const Vec3& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
  [[nodiscard]] bool overlaps(const Box& o) const {
    return (min.array() <= o.max.array()).all() && (o.min.array() <= max.array()).all();
  }
};

/// A box in a frame of its own: the points `center + axes * q` with |q_k| <= half_k (axes: orthonormal
/// columns). How a volume with an orientation (an OBB) describes itself to the ADB density
/// (volumes/concept.hpp, `oriented_box()`); empty when a half-extent is negative.
struct OrientedBox {
  Mat3 axes = Mat3::Identity();
  Vec3 center = Vec3::Zero();
  Vec3 half = Vec3::Constant(-1);

  [[nodiscard]] bool empty() const { return (half.array() < 0).any(); }
  /// p in the box's own coordinates (the same expression as the OBB's containment test).
  [[nodiscard]] Vec3 local(const Vec3& p) const { return axes.transpose() * (p - center); }
};

/// Rigid motion x -> R x + t. R must be a proper rotation; `checked` enforces it for caller input.
struct RigidTransform {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();

  [[nodiscard]] Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
  [[nodiscard]] RigidTransform inverse() const {
    RigidTransform inv;
    inv.rotation = rotation.transpose();
    inv.translation = -(inv.rotation * translation);
    return inv;
  }
  /// (this * other)(x) = this(other(x)).
  [[nodiscard]] RigidTransform operator*(const RigidTransform& other) const {
    RigidTransform out;
    out.rotation = rotation * other.rotation;
    out.translation = rotation * other.translation + translation;
    return out;
  }

  static RigidTransform identity() { return {}; }
  static RigidTransform translate(const Vec3& t) {
    RigidTransform out;
    out.translation = t;
    return out;
  }

  /// Throws std::invalid_argument naming the defect unless the entries are finite, R^T R = I within
  /// `tolerance` and det R = +1. Queries call it once each: a NaN or scaled matrix would otherwise make
  /// every overlap test false and return a silent, "exact" no.
  void validate(Scalar tolerance = 1e-9) const;

  /// Validated construction from caller input (see validate); never returns a non-rigid transform.
  static RigidTransform checked(const Mat3& rotation, const Vec3& translation, Scalar tolerance = 1e-9) {
    const RigidTransform t{rotation, translation};
    t.validate(tolerance);
    return t;
  }
};

/// Two boxes in frames of their own, as a pair lies: each one's half-extents, and B's box frame in A's box
/// frame (B's axes as columns and B's centre, in A's box coordinates). What an oriented box's overlap test
/// computes first, handed on to the ADB estimate in the nodes' frames (volumes/concept.hpp).
struct PlacedBoxes {
  Vec3 half_a = Vec3::Constant(-1);
  Vec3 half_b = Vec3::Constant(-1);
  RigidTransform b_in_a;

  [[nodiscard]] bool empty() const { return (half_a.array() < 0).any() || (half_b.array() < 0).any(); }
};

}  // namespace bvhlab
