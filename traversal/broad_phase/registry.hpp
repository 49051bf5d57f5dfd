// The broad phases by name, for tools that choose one at run time. A new broad phase is one header
// (a model of BroadPhase, broad_phase.hpp) and one entry in RegisteredBroadPhases below.
#pragma once

#include "../../volumes/type_list.hpp"
#include "broad_phase.hpp"
#include "brute_force.hpp"
#include "dynamic_aabb_tree.hpp"
#include "sweep_and_prune.hpp"

#include <memory>

namespace bvhlab {

using RegisteredBroadPhases = TypeList<BruteForce, SweepAndPrune, DynamicAabbTree>;

/// A broad phase chosen at run time: the concept's operations behind one virtual call per frame.
class AnyBroadPhase {
 public:
  virtual ~AnyBroadPhase() = default;
  [[nodiscard]] virtual std::string_view name() const = 0;
  virtual void update(std::span<const Box> world_boxes) = 0;
  [[nodiscard]] virtual const std::vector<ObjectPair>& pairs() const = 0;
};

namespace broad_phase_detail {

template <BroadPhase B>
class Holder final : public AnyBroadPhase {
 public:
  [[nodiscard]] std::string_view name() const override { return B::name(); }
  void update(std::span<const Box> world_boxes) override { model_.update(world_boxes); }
  [[nodiscard]] const std::vector<ObjectPair>& pairs() const override { return model_.pairs(); }

 private:
  B model_;
};

}  // namespace broad_phase_detail

/// The registered broad phases' names, in registry order.
inline std::vector<std::string> broad_phase_names() {
  return type_names(RegisteredBroadPhases{});
}

/// A fresh broad phase (default options) by name; std::invalid_argument listing the known names otherwise.
inline std::unique_ptr<AnyBroadPhase> make_broad_phase(std::string_view name) {
  return with_named_type(
      "broad phase", name,
      []<class B>(std::type_identity<B>) -> std::unique_ptr<AnyBroadPhase> {
        return std::make_unique<broad_phase_detail::Holder<B>>();
      },
      RegisteredBroadPhases{});
}

}  // namespace bvhlab
