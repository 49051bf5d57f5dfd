// Typed-test lists derived from the one list of shipped volumes (volumes/shipped.hpp): a model added there is
// tested everywhere it qualifies without being named again.
#pragma once

#include "volumes/concept.hpp"
#include "volumes/shipped.hpp"

#include <gtest/gtest.h>

#include <type_traits>

namespace bvhlab::testing {

/// Concatenation of ::testing::Types lists.
template <class... Lists>
struct ConcatTypes {
  using type = ::testing::Types<>;
};
template <class... A>
struct ConcatTypes<::testing::Types<A...>> {
  using type = ::testing::Types<A...>;
};
template <class... A, class... B, class... Rest>
struct ConcatTypes<::testing::Types<A...>, ::testing::Types<B...>, Rest...>
    : ConcatTypes<::testing::Types<A..., B...>, Rest...> {};

/// The types of `List` (a TypeList) for which Keep<T>::value holds, in order, as ::testing::Types.
template <template <class> class Keep, class List>
struct SelectTypes;
template <template <class> class Keep, class... Ts>
struct SelectTypes<Keep, TypeList<Ts...>>
    : ConcatTypes<std::conditional_t<Keep<Ts>::value, ::testing::Types<Ts>, ::testing::Types<>>...> {};

/// Self-contained models (BoundingVolume); the others are stored relative to their parent.
template <class BV>
struct IsSelfContained : std::bool_constant<BoundingVolume<BV>> {};

/// Every shipped self-contained model.
using ShippedBoundingVolumes = SelectTypes<IsSelfContained, ShippedVolumes>::type;

/// Every shipped model, the hierarchical ones (restricted boxtree) included.
template <class BV>
struct AnyVolume : std::true_type {};
using AllShippedVolumes = SelectTypes<AnyVolume, ShippedVolumes>::type;

/// The volumes the traversal tests run over. The sanitizer builds (BVHLAB_LEAN_VOLUMES) keep one k-DOP for
/// the family: the k-DOPs share one template, their volume tests still cover every direction table, and the
/// other four would double the sanitized compile and run time of these tests. Release runs them all.
#ifdef BVHLAB_LEAN_VOLUMES
using TraversalTestVolumes = SelectTypes<AnyVolume, LeanVolumes>::type;
#else
using TraversalTestVolumes = AllShippedVolumes;
#endif

/// Every other type of a ::testing::Types list, from position `First` (0 or 1): the two halves of a typed
/// suite instantiated in two files, so that both cores compile it.
template <int First, class List>
struct AlternateTypes {
  using type = ::testing::Types<>;
};
template <class A, class... Rest>
struct AlternateTypes<0, ::testing::Types<A, Rest...>>
    : ConcatTypes<::testing::Types<A>, typename AlternateTypes<1, ::testing::Types<Rest...>>::type> {};
template <class A, class... Rest>
struct AlternateTypes<1, ::testing::Types<A, Rest...>> : AlternateTypes<0, ::testing::Types<Rest...>> {};

}  // namespace bvhlab::testing
