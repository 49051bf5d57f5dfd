// Errors thrown by code compiled once per policy combination, built out of line: each instantiation that
// threw a concatenated message compiled its own string code (engine/typed_query.hpp).
#pragma once

#include <initializer_list>
#include <string_view>

namespace bvhlab::engine_detail {

/// Throws std::logic_error with `parts` joined: an internal check failed (a bug, not bad input).
[[noreturn]] void throw_logic_error(std::initializer_list<std::string_view> parts);

}  // namespace bvhlab::engine_detail
