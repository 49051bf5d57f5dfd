// Monte Carlo estimate of LB, the probability that the polygons in one collision cell really intersect.
//
// Model. A collision cell holds at least tau * c^2 polygon area of each object (c = cell side; the
// annotation's threshold). Each object's surface in the cell is modelled as one planar patch: a random
// plane hitting the cell, clipped to it, kept only if the clipped area is at least tau * c^2. LB(tau) is
// the probability that two independent such patches intersect inside the cell. Cells are scaled to the
// unit cube [0, 1]^3; the result does not depend on c.
//
// Why random planes. At cell scale a tessellated surface that fills a good fraction of the cell is close
// to flat, and the ADB average-case assumption already treats the position and orientation of geometry
// relative to the grid as random. "Random" is taken as the motion-invariant measure of planes (uniform
// in normal direction and offset jointly, conditioned on hitting the cell), the one measure under
// which the answer does not depend on how the grid happens to be aligned; integral geometry then gives
// checkable values (mean section area 2/3, and LB(0) = pi / 6, see the tests).
// Weakness. Real surfaces in a cell are curved, folded or split into several sheets (a thin wall gives two
// parallel sheets, a corner two planes); several sheets of the same total area intersect a second surface
// more often than one flat patch, a folded one less predictably. Conditioning on area >= tau also favours
// planes through the cell's middle. So LB is a model constant, not a guaranteed bound.
//
// Reproducibility. Random numbers come from std::mt19937_64 (its output sequence is fixed by the
// standard) mapped to [0, 1) by taking the top 53 bits, not std::uniform_real_distribution (whose output
// is implementation-defined). The geometry uses only +, -, *, / and sqrt (correctly rounded in IEEE 754)
// and its source is compiled with -ffp-contract=off, so a given seed gives the same counts everywhere.
#pragma once

#include <array>
#include <cstdint>
#include <random>

namespace bvhlab {

using Point3d = std::array<double, 3>;

/// Plane {p : dot(normal, p) = offset} with a unit normal.
struct CellPlane {
  Point3d normal{0.0, 0.0, 1.0};
  double offset = 0.0;
};

/// A plane clipped to the unit cube: a convex polygon of 3 to 6 vertices in order; count < 3 (and no
/// vertices) when the plane misses the cube or only touches it.
struct CubeSection {
  std::array<Point3d, 6> vertices{};
  int count = 0;
};

/// Clips the plane against [0, 1]^3 (in double: a statistics tool, not the exact annotation).
CubeSection clip_plane_to_unit_cube(const CellPlane& plane);

/// Area of a planar convex polygon whose plane has the given unit normal; 0 for fewer than 3 vertices.
double section_area(const CubeSection& section, const Point3d& unit_normal);

/// Whether two patches P = plane_p ∩ cube and Q meet: P ∩ Q = plane_p ∩ Q, and Q is convex, so they meet
/// exactly when Q's vertices are not all strictly on one side of plane_p.
bool patch_meets_plane(const CubeSection& patch, const CellPlane& plane);

/// Uniform double in [0, 1) from the top 53 bits of one mt19937_64 output.
inline double unit_uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

/// Draws a plane hitting the unit cube from the motion-invariant measure (uniform in direction and offset
/// jointly, conditioned on hitting): the normal uniform on the sphere (rejection from [-1, 1]^3, no
/// trigonometry), the offset uniform over the circumscribed sphere's range, misses rejected. Drawing the
/// offset over the cube's own extent instead would under-weight directions in which the cube is wide.
CellPlane random_plane_hitting_unit_cube(std::mt19937_64& rng);

struct LbMonteCarloResult {
  double tau = 0.0;
  std::uint64_t seed = 0;
  std::uint64_t pairs = 0;         ///< accepted patch pairs tested
  std::uint64_t hits = 0;          ///< pairs whose patches intersect
  std::uint64_t planes_drawn = 0;  ///< including those rejected for too small an area
  [[nodiscard]] double probability() const;
  [[nodiscard]] double standard_error() const;  ///< binomial sqrt(p (1 - p) / pairs)
};

/// Runs the experiment for one threshold tau (area as a fraction of c^2; a plane section of the unit cube
/// has area at most sqrt(2)). Throws std::invalid_argument for tau outside [0, 1.4] (larger thresholds
/// accept almost nothing) or pairs == 0.
LbMonteCarloResult run_lb_monte_carlo(double tau, std::uint64_t pairs, std::uint64_t seed);

}  // namespace bvhlab
