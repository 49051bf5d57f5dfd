// Compile-time lists of policy types, and the one way a run-time name picks one of them. Every registry
// (volumes, densities and strategies in engine/registry.hpp, density updates in adb/update.hpp, broad phases
// in traversal/broad_phase/registry.hpp) looks names up here, so an unknown name reads the same everywhere:
//   unknown <kind> '<name>' (known: <a>, <b>, ...)
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace bvhlab {

/// A compile-time list of types.
template <class... Ts>
struct TypeList {};

template <class... Ts>
constexpr std::size_t type_list_size(TypeList<Ts...>) {
  return sizeof...(Ts);
}

template <std::size_t I, class List>
struct TypeAtList;
template <std::size_t I, class... Ts>
struct TypeAtList<I, TypeList<Ts...>> {
  using type = std::tuple_element_t<I, std::tuple<Ts...>>;
};
/// The I-th type of a list.
template <std::size_t I, class List>
using TypeAt = typename TypeAtList<I, List>::type;

/// T's position in the list (its size when T is not in it).
template <class T, class... Ts>
constexpr std::size_t type_index(TypeList<Ts...>) {
  std::size_t i = 0;
  (void)((std::is_same_v<T, Ts> ? false : (++i, true)) && ...);
  return i;
}

/// Each type's name(), in list order.
template <class... Ts>
std::vector<std::string> type_names(TypeList<Ts...>) {
  return {std::string(Ts::name())...};
}

/// "a, b, c".
inline std::string joined_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// The one error for an unknown name: "unknown <kind> '<name>' (known: <names>)".
inline std::invalid_argument unknown_name(std::string_view kind, std::string_view name,
                                          const std::vector<std::string>& known) {
  return std::invalid_argument("unknown " + std::string(kind) + " '" + std::string(name) +
                               "' (known: " + joined_names(known) + ")");
}

/// Calls f(std::type_identity<T>{}) for every T of the list, in order.
template <class F, class... Ts>
void for_each_type(F&& f, TypeList<Ts...>) {
  (f(std::type_identity<Ts>{}), ...);
}

/// Calls f(std::type_identity<T>{}) for the T of the list whose name() is `name` and returns what f returns;
/// throws unknown_name(kind, ...) when there is none.
template <class F, class... Ts>
auto with_named_type(std::string_view kind, std::string_view name, F&& f, TypeList<Ts...> list) {
  using First = std::tuple_element_t<0, std::tuple<Ts...>>;
  using R = decltype(f(std::type_identity<First>{}));
  if constexpr (std::is_void_v<R>) {
    bool found = false;
    ((found = found || (Ts::name() == name ? (f(std::type_identity<Ts>{}), true) : false)), ...);
    if (!found) throw unknown_name(kind, name, type_names(list));
  } else {
    std::optional<R> out;
    ((out || Ts::name() != name ? void() : void(out.emplace(f(std::type_identity<Ts>{})))), ...);
    if (!out) throw unknown_name(kind, name, type_names(list));
    return std::move(*out);
  }
}

}  // namespace bvhlab
