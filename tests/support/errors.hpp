// The message of the exception a call throws, for tests that check what an error names.
#pragma once

#include <exception>
#include <string>

namespace bvhlab::testing {

/// What `f()` threw (any std::exception), or "(no error)".
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace bvhlab::testing
