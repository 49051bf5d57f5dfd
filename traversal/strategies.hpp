// The shipped traversal strategies with the loops they run: include this to call S::query. The
// declarations alone (what the registry needs) are in traversal/strategy_types.hpp.
#pragma once

#include "adb.hpp"
#include "coherent.hpp"
#include "coherent_adb.hpp"
#include "distance.hpp"
#include "exact.hpp"
#include "strategy_types.hpp"
#include "wide_adb.hpp"
#include "wide_distance.hpp"
#include "wide_exact.hpp"
