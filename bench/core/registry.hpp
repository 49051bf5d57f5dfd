// The one place where run-time names meet compile-time policies: bounding volumes, densities and traversal
// strategies. A new policy is named here (one line in its list) and nowhere else outside its own header;
// tools instantiate only what they are asked for.
#pragma once

#include "adb/adb_density.hpp"
#include "adb/adb_normal_density.hpp"
#include "adb/adb_paper_density.hpp"
#include "adb/tree.hpp"
#include "traversal/strategies.hpp"
#include "volumes/shipped.hpp"

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#ifdef BVHLAB_TEST_POLICIES
// The test-only policies (tests/support/): built into the test variant of the runner and CLI only.
#include "tests/support/test_density.hpp"
#include "tests/support/test_strategy.hpp"
#endif

namespace bvhlab {

/// The shipped volume models, listed once in volumes/shipped.hpp (the typed volume tests use that list too).
#if defined(BVHLAB_TEST_POLICIES)
/// The test variant proves the density and strategy axes, not the volumes: two volumes keep its second copy
/// of the runner and CLI cheap to compile (every volume multiplies the density x strategy instantiations).
using RegisteredVolumes = TypeList<Aabb, Obb>;
#elif defined(BVHLAB_LEAN_VOLUMES)
/// The sanitizer builds (BVHLAB_LEAN_VOLUMES): one k-DOP stands for its family, the same template with other
/// direction tables. The runner's instantiations are most of a sanitized build's time.
using RegisteredVolumes = TypeList<Aabb, Dop24, Obb, Sphere, RestrictedBox>;
#else
using RegisteredVolumes = ShippedVolumes;
#endif

#ifndef BVHLAB_TEST_POLICIES
using RegisteredDensities = TypeList<NoDensity, AdbDensity, AdbPaperDensity, AdbNormalDensity>;
using RegisteredStrategies =
    TypeList<ExactStrategy, AllContactsStrategy, GuidedExactStrategy, AdbStrategy, TimeCriticalStrategy,
             GuidedExactDfsStrategy, AdbDfsStrategy, AdbLargerStrategy>;
#else
/// The test variant adds one density and one strategy next to a few shipped ones: enough to show that a new
/// policy needs nothing but its header and its line, while each left-out policy saves its instantiations
/// in this second copy of the runner and CLI.
using RegisteredDensities = TypeList<NoDensity, AdbDensity, testing::TriangleCountDensity>;
using RegisteredStrategies = TypeList<ExactStrategy, AllContactsStrategy, GuidedExactStrategy, AdbStrategy,
                                      TimeCriticalStrategy, testing::RootOverlapStrategy>;
#endif

namespace registry_detail {

template <class... Ts>
std::vector<std::string> names(TypeList<Ts...>) {
  return {std::string(Ts::name())...};
}

inline std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// Calls f(std::type_identity<T>{}) for the T of the list whose name() is `name`; throws naming the choices.
template <class F, class... Ts>
auto with_named(std::string_view kind, std::string_view name, F&& f, TypeList<Ts...> list) {
  auto unknown = [&] {
    return std::invalid_argument("unknown " + std::string(kind) + " '" + std::string(name) +
                                 "' (known: " + joined(names(list)) + ")");
  };
  using First = std::tuple_element_t<0, std::tuple<Ts...>>;
  using R = decltype(f(std::type_identity<First>{}));
  if constexpr (std::is_void_v<R>) {
    bool found = false;
    ((found = found || (Ts::name() == name ? (f(std::type_identity<Ts>{}), true) : false)), ...);
    if (!found) throw unknown();
  } else {
    std::optional<R> out;
    ((out || Ts::name() != name ? void() : void(out.emplace(f(std::type_identity<Ts>{})))), ...);
    if (!out) throw unknown();
    return *out;
  }
}

template <class F, class... Ts>
void for_each(F&& f, TypeList<Ts...>) {
  (f(std::type_identity<Ts>{}), ...);
}

}  // namespace registry_detail

/// Calls f(std::type_identity<BV>{}) for the BV whose name() is `name`; throws naming the choices.
template <class F>
auto with_volume(std::string_view name, F&& f) {
  return registry_detail::with_named("bounding volume", name, std::forward<F>(f), RegisteredVolumes{});
}
/// Calls f(std::type_identity<BV>{}) for every registered BV, in registration order.
template <class F>
void with_each_volume(F&& f) {
  registry_detail::for_each(std::forward<F>(f), RegisteredVolumes{});
}
inline std::vector<std::string> volume_names() {
  return registry_detail::names(RegisteredVolumes{});
}

/// Calls f(std::type_identity<D>{}) for the density whose name() is `name`; throws naming the choices.
template <class F>
auto with_density(std::string_view name, F&& f) {
  return registry_detail::with_named("density", name, std::forward<F>(f), RegisteredDensities{});
}
template <class F>
void with_each_density(F&& f) {
  registry_detail::for_each(std::forward<F>(f), RegisteredDensities{});
}
inline std::vector<std::string> density_names() {
  return registry_detail::names(RegisteredDensities{});
}

/// Calls f(std::type_identity<S>{}) for the strategy whose name() is `name`; throws naming the choices.
template <class F>
auto with_strategy(std::string_view name, F&& f) {
  return registry_detail::with_named("strategy", name, std::forward<F>(f), RegisteredStrategies{});
}
template <class F>
void with_each_strategy(F&& f) {
  registry_detail::for_each(std::forward<F>(f), RegisteredStrategies{});
}
inline std::vector<std::string> strategy_names() {
  return registry_detail::names(RegisteredStrategies{});
}

}  // namespace bvhlab
