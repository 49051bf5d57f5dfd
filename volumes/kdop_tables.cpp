// The shipped direction sets' tables (volumes/kdop_tables.hpp), compiled here once: every file that uses a
// k-DOP otherwise derived them again, the prototype's vertices and triples with Eigen's inverses.
#include "kdop_tables.hpp"

namespace bvhlab::dop_detail {

template struct Tables<3>;
template struct Tables<7>;
template struct Tables<9>;
template struct Tables<12>;
template struct Tables<13>;

}  // namespace bvhlab::dop_detail
