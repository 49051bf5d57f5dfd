#include "engine/deforming.hpp"

#include "engine/tree_model.hpp"

#include <stdexcept>

namespace bvhlab {

DeformingTree::DeformingTree(const Mesh& rest, const std::string& bv, const BuildOptions& options)
    : tree_(AnyTree::build(rest, MeshUnits{}, bv, DensitySpec{}, options)), options_(options) {}

double DeformingTree::refit(const Mesh& deformed, RefitMethod method) {
  if (tree_.model().use_count() != 1)
    throw std::logic_error("refit: a prepared query or a copy of the handle still holds the tree");
  // The model was made non-const by the build; this handle is its only owner.
  return std::const_pointer_cast<engine_detail::TreeModel>(tree_.model())->refit(deformed, method);
}

void DeformingTree::rebuild(const Mesh& deformed) {
  const TreeInfo& info = tree_.info();
  tree_ = AnyTree::build(deformed, info.units, info.bv, DensitySpec{}, options_);
}

FollowingDensity::FollowingDensity(const DensityUpdateSpec& spec, const AnyTree& annotated_rest)
    : model_(annotated_rest.model()->follow(spec)) {}
FollowingDensity::FollowingDensity(FollowingDensity&&) noexcept = default;
FollowingDensity& FollowingDensity::operator=(FollowingDensity&&) noexcept = default;
FollowingDensity::~FollowingDensity() = default;

void FollowingDensity::check_unshared(const char* what) const {
  if (model_->model().use_count() > 2)  // the follower's own pointer and the one just made
    throw std::logic_error(std::string(what) + ": a prepared query or a handle still holds the tree");
}

void FollowingDensity::take_volumes(const AnyTree& refitted) {
  check_unshared("take_volumes");
  model_->take_volumes(*refitted.model());
}

DensityUpdateStats FollowingDensity::update() {
  check_unshared("update");
  return model_->update();
}

void FollowingDensity::restart() {
  check_unshared("restart");
  model_->restart();
}

CountError FollowingDensity::count_error(const AnyTree& exact) const {
  return model_->count_error(*exact.model());
}

AnyTree FollowingDensity::tree() const {
  return AnyTree(model_->model());
}

}  // namespace bvhlab
