// What a volume's free query file (volume_free_queries.cpp.in) compiles: the density-free strategies'
// loops (engine/typed_query.hpp). Internal to engine/.
#pragma once

#include "engine/typed_query.hpp"
#include "traversal/coherent.hpp"
#include "traversal/distance.hpp"
#include "traversal/exact.hpp"
#include "traversal/wide_distance.hpp"
#include "traversal/wide_exact.hpp"
