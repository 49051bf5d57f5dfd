// The exact traversal's option (traversal/exact.hpp), apart from its loop: the strategies' declarations
// (traversal/strategy_types.hpp) name it without compiling the loop.
#pragma once

namespace bvhlab {

/// Stop at the first intersecting triangle pair, or list all of them.
enum class ContactMode { First, All };

}  // namespace bvhlab
