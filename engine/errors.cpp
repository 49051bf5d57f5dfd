#include "engine/errors.hpp"

#include <stdexcept>
#include <string>

namespace bvhlab::engine_detail {

void throw_logic_error(std::initializer_list<std::string_view> parts) {
  std::string message;
  for (const std::string_view part : parts) message += part;
  throw std::logic_error(message);
}

}  // namespace bvhlab::engine_detail
