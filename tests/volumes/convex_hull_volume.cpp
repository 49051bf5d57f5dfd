#include "convex_hull_volume.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <cmath>
#include <vector>

namespace bvhlab::volume_tests {

double convex_hull_volume(std::span<const Vec3> points) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = Kernel::Point_3;
  if (points.size() < 4) return 0;
  std::vector<Point> input;
  input.reserve(points.size());
  for (const Vec3& p : points) input.emplace_back(p.x(), p.y(), p.z());
  CGAL::Surface_mesh<Point> hull;
  CGAL::convex_hull_3(input.begin(), input.end(), hull);
  if (hull.number_of_faces() < 4) return 0;
  // Sum of tetrahedra from one hull vertex over the (triangulated) faces.
  const Point origin = hull.point(*hull.vertices().begin());
  double volume = 0;
  for (auto face : hull.faces()) {
    std::vector<Point> corners;
    for (auto v : CGAL::vertices_around_face(hull.halfedge(face), hull)) corners.push_back(hull.point(v));
    for (std::size_t k = 1; k + 1 < corners.size(); ++k)
      volume += CGAL::to_double(CGAL::volume(origin, corners[0], corners[k], corners[k + 1]));
  }
  return std::abs(volume);
}

}  // namespace bvhlab::volume_tests
