// What bench/bench_bv_test.cpp calls: one volume's series on one mesh. Declared here, defined in
// series_impl.hpp and instantiated in the part files, so that the volumes' series compile in two units.
#pragma once

#include "bvh/mesh.hpp"
#include "volumes/geometry.hpp"

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace bvhlab::bv_test {

/// The series are compiled in kParts units, each for the registered volumes whose index is its part modulo
/// kParts.
inline constexpr std::size_t kParts = 2;

/// Registers the series of `volume` on `mesh` over `poses` (which must outlive the benchmark run) when the
/// volume falls to unit `Part` (series_part<Part>.cpp); false when it falls to another. Throws
/// std::invalid_argument naming the registered volumes for an unknown one.
template <std::size_t Part>
bool register_volume_part(const std::string& volume, const std::string& mesh_name,
                          const std::shared_ptr<const Mesh>& mesh, const std::vector<RigidTransform>& poses);

}  // namespace bvhlab::bv_test
