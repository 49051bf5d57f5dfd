#include "engine/any_tree.hpp"

#include "adb/saved_tree.hpp"
#include "engine/policies.hpp"
#include "engine/registry.hpp"
#include "engine/tree_model.hpp"
#include "traversal/frame_budget.hpp"

#include <cstdio>
#include <stdexcept>

namespace bvhlab {

namespace fs = std::filesystem;
using engine_detail::ModelPtr;
using engine_detail::PairOps;

#if !defined(BVHLAB_VOLUME_SLOTS) || !defined(BVHLAB_DENSITY_SLOTS)
#error "engine/CMakeLists.txt defines BVHLAB_VOLUME_SLOTS and BVHLAB_DENSITY_SLOTS: the files it generates"
#endif
static_assert(type_list_size(RegisteredVolumes{}) <= BVHLAB_VOLUME_SLOTS,
              "more registered volumes than slots: raise the volume slots in engine/CMakeLists.txt");
static_assert(type_list_size(RegisteredDensities{}) <= BVHLAB_DENSITY_SLOTS,
              "more registered densities than slots: raise the density slots in engine/CMakeLists.txt");

namespace {

/// The operations of the registered volume `bv` with density `density`; throws naming the choices.
const PairOps& ops_of(std::string_view bv, std::string_view density) {
  return *with_volume(bv, [&]<class BV>(std::type_identity<BV>) {
    return with_density(density, []<class D>(std::type_identity<D>) {
      constexpr std::size_t v = type_index<BV>(RegisteredVolumes{}), d = type_index<D>(RegisteredDensities{});
      if constexpr (engine_detail::slot_compiled(v, d))
        return &engine_detail::slot_ops<v, d>();
      else
        return &engine_detail::left_out_ops<v, d, engine_detail::slot_compiled(v, 0)>();  // 0: none
    });
  });
}

/// Refuses a mesh in other units than the saved tree's: its polygons would not be where the tree's leaves
/// are.
void check_mesh_units(const MeshUnits& tree, const UnitMesh& mesh, const fs::path& file) {
  if (mesh.units == tree) return;
  throw std::invalid_argument("saved tree '" + file.string() + "' and mesh '" + mesh.name +
                              "' differ in units (tree: " + tree.describe() +
                              "; mesh: " + mesh.units.describe() +
                              "); give the mesh as the tree was built (load_mesh(normalize=...))");
}

}  // namespace

std::string MeshUnits::describe() const {
  if (scaled_by == 1) return file.describe();
  char factor[32];
  std::snprintf(factor, sizeof factor, "%.6g", scaled_by);
  return file.describe() + ", then scaled by " + factor;
}

void check_same_kind_of_units(const TreeInfo& a, const TreeInfo& b) {
  if (a.units.file.normalized == b.units.file.normalized) return;
  throw std::invalid_argument("the trees are in different units (a: " + a.units.describe() +
                              "; b: " + b.units.describe() + "); normalise both meshes or neither");
}

AnyTree AnyTree::build(const Mesh& mesh, const MeshUnits& units, const std::string& bv,
                       const DensitySpec& density, const BuildOptions& options) {
  return AnyTree(ops_of(bv, density.name).build(mesh, units, density, options));
}

AnyTree AnyTree::build_points(const UnitCloud& cloud, const std::string& bv, const DensitySpec& density,
                              const BuildOptions& options) {
  return AnyTree(ops_of(bv, density.name).build_points(cloud, density, options));
}

namespace {

/// The operations of the volume and density a saved tree's header names; SavedTreeError naming `source`
/// for names this build does not know.
const PairOps& saved_ops(const saved_tree_detail::Header& header, const std::string& source) {
  try {
    return ops_of(header.bv_name, header.density_name);
  } catch (const std::invalid_argument& e) {
    throw SavedTreeError("saved tree '" + source + "': " + e.what());
  }
}

}  // namespace

AnyTree AnyTree::from_bytes(std::span<const std::byte> bytes, const std::string& source, const Mesh* mesh) {
  const saved_tree_detail::Header header = saved_tree_detail::read_header(bytes, source);
  return AnyTree(saved_ops(header, source).load(bytes, source, mesh, MeshUnits{header.units, 1}));
}

AnyTree AnyTree::load(const fs::path& file, const UnitMesh* mesh) {
  const std::vector<std::byte> bytes = saved_tree_detail::read_file(file);
  const saved_tree_detail::Header header = saved_tree_detail::read_header(bytes, file.string());
  const PairOps& ops = saved_ops(header, file.string());
  const MeshUnits units{header.units, 1};
  if (mesh) check_mesh_units(units, *mesh, file);
  try {
    return AnyTree(ops.load(bytes, file.string(), mesh, units));
  } catch (const SavedTreeError&) {
    throw;
  } catch (const std::runtime_error& e) {  // the structural checks of the mesh's fit
    if (!mesh) throw;
    throw std::invalid_argument("saved tree '" + file.string() + "' does not fit mesh '" + mesh->name +
                                "': " + e.what());
  }
}

AnyTree AnyTree::annotated(const DensitySpec& density, const AnnotationContext& context,
                           AnnotateStats* stats) const {
  const TreeInfo& plain = model_->info;
  if (plain.density != "none")
    throw std::logic_error("annotated: the tree already carries " + plain.annotation);
  if (plain.points) throw std::logic_error("annotated: a tree over points is annotated when it is built");
  return AnyTree(ops_of(plain.bv, density.name).annotate(*model_, density, context, stats));
}

std::vector<std::byte> AnyTree::save_bytes(const std::string& source) const {
  return model_->save_bytes(source);
}

void AnyTree::save(const fs::path& file) const {
  const MeshUnits& units = model_->info.units;
  if (units.scaled_by != 1)
    throw std::invalid_argument("cannot save '" + file.string() + "': the tree's units (" + units.describe() +
                                ") include load_mesh's scale, and a saved tree records only the mesh file's "
                                "units or the normalisation; build it from a mesh loaded without scale=");
  saved_tree_detail::write_file_atomically(file, model_->save_bytes(file.string()));
}

const TreeInfo& AnyTree::info() const {
  return model_->info;
}

double AnyTree::wide_layout_bytes() const {
  return model_->wide_layout_bytes();
}

Box AnyTree::world_box(const RigidTransform& pose) const {
  return model_->world_box(pose);
}

std::unique_ptr<PreparedQuery> AnyTree::prepare(const AnyTree& b, const StrategyVariant& variant) const {
  return model_->prepare(model_, b.model_, variant);
}

std::vector<PairOutcome> AnyTree::schedule_frame(std::span<const FramePairRef> pairs,
                                                 const FrameOptions& options, FrameMemory* memory) {
  if (pairs.empty()) return {};
  return pairs.front().a->model_->schedule(pairs, options, memory);
}

}  // namespace bvhlab
