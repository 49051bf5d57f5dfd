#include "adb/lb_table.hpp"

#include <stdexcept>
#include <string>

#include "adb/lb_table_data.hpp"

namespace bvhlab {

std::span<const LbTableRow> lb_table() {
  return kLbTable;
}

double lb_for_tau(double tau) {
  const std::span<const LbTableRow> rows = lb_table();
  if (!(tau >= rows.front().tau && tau <= rows.back().tau)) {
    throw std::invalid_argument("lb_for_tau: tau = " + std::to_string(tau) + " is outside the tabulated [" +
                                std::to_string(rows.front().tau) + ", " + std::to_string(rows.back().tau) +
                                "]");
  }
  for (std::size_t i = 0; i + 1 < rows.size(); ++i) {
    if (tau <= rows[i + 1].tau) {
      const double t = (tau - rows[i].tau) / (rows[i + 1].tau - rows[i].tau);
      return rows[i].lb() + t * (rows[i + 1].lb() - rows[i].lb());
    }
  }
  return rows.back().lb();
}

}  // namespace bvhlab
