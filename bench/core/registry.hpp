// The one place where run-time names meet compile-time BV policies: the shipped models (listed once, in
// volumes/shipped.hpp) by their names. Tools instantiate only what they are asked for.
#pragma once

#include "volumes/shipped.hpp"

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

using RegisteredVolumes = ShippedVolumes;

/// Calls f(std::type_identity<BV>{}) for the BV whose name() is `name`; throws naming the choices.
template <class F, class... BVs>
auto with_volume_impl(std::string_view name, F&& f, TypeList<BVs...>) {
  using R = decltype(f(std::type_identity<Aabb>{}));
  if constexpr (std::is_void_v<R>) {
    bool found = false;
    ((found = found || (BVs::name() == name ? (f(std::type_identity<BVs>{}), true) : false)), ...);
    if (!found) throw std::invalid_argument("unknown bounding volume '" + std::string(name) + "'");
  } else {
    std::optional<R> out;
    ((out || BVs::name() != name ? void() : void(out.emplace(f(std::type_identity<BVs>{})))), ...);
    if (!out) throw std::invalid_argument("unknown bounding volume '" + std::string(name) + "'");
    return *out;
  }
}
template <class F>
auto with_volume(std::string_view name, F&& f) {
  return with_volume_impl(name, std::forward<F>(f), RegisteredVolumes{});
}

/// Calls f(std::type_identity<BV>{}) for every registered BV, in registration order.
template <class F, class... BVs>
void with_each_volume_impl(F&& f, TypeList<BVs...>) {
  (f(std::type_identity<BVs>{}), ...);
}
template <class F>
void with_each_volume(F&& f) {
  with_each_volume_impl(std::forward<F>(f), RegisteredVolumes{});
}

template <class... BVs>
std::vector<std::string> volume_names_impl(TypeList<BVs...>) {
  return {std::string(BVs::name())...};
}
inline std::vector<std::string> volume_names() {
  return volume_names_impl(RegisteredVolumes{});
}

}  // namespace bvhlab
