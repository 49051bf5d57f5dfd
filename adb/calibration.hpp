// Per-series calibration of reported probabilities: a monotone map from the probability a strategy reports
// to the collision frequency observed for it, fitted by isotonic regression (pool adjacent violators) on
// (probability, collided) samples of a training pose set.
//
// The map is piecewise linear through its knots, non-decreasing and within [0, 1]: two per pooled block, at
// the lowest and the highest probability the block holds, both at its observed frequency (one when the
// block holds a single probability), so that every training answer maps to its block's frequency and the
// map only interpolates between blocks. Where the training set had no samples it
// falls back to the identity: below the first knot it runs linearly from (0, 0), above the last one to
// (1, 1), and a map without knots is the identity. Monotone by construction: ranking answers by probability
// is the same before and after the map (up to ties).
//
// Encoding (every integer little-endian, doubles as their IEEE bits):
//   magic "BVHLCAL1" (8) | knot count K (u32) | reserved 0 (u32) | K x (x, y) (2 doubles) | FNV-1a 64 of all
//   bytes before it (8)
// Decoding refuses, by name, a short or long buffer, a wrong magic, a checksum mismatch, and knots that are
// not finite, outside [0, 1], not strictly increasing in x or decreasing in y: such a map is never applied.
#pragma once

#include <cstddef>
#include <span>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace bvhlab {

/// A refused calibration map or sample; what() names the source and the problem.
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One training answer: the probability reported and whether the pose truly collides.
struct CalibrationSample {
  double probability = 0;
  bool collided = false;
};

class CalibrationMap {
 public:
  /// A point of the map: reported probability x, calibrated probability y.
  struct Knot {
    double x = 0, y = 0;
    bool operator==(const Knot&) const = default;
  };

  /// The identity.
  CalibrationMap() = default;
  /// From knots; throws CalibrationError unless they are finite, in [0, 1], x strictly increasing and y
  /// non-decreasing.
  explicit CalibrationMap(std::vector<Knot> knots);

  /// Isotonic regression of `collided` on `probability` (equal probabilities pooled first, since a map gives
  /// them one value). Throws CalibrationError for a probability that is not a number in [0, 1].
  static CalibrationMap fit(std::span<const CalibrationSample> samples);

  /// The calibrated probability of a reported one (clamped to [0, 1] first; NaN stays NaN).
  [[nodiscard]] double operator()(double probability) const;
  [[nodiscard]] const std::vector<Knot>& knots() const { return knots_; }
  [[nodiscard]] bool identity() const { return knots_.empty(); }

  [[nodiscard]] std::vector<std::byte> encode() const;
  /// Throws CalibrationError "SOURCE: problem" for anything encode() would not have written.
  static CalibrationMap decode(std::span<const std::byte> bytes, std::string_view source);

 private:
  std::vector<Knot> knots_;
};

}  // namespace bvhlab
