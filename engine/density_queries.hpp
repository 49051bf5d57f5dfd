// What a slot's query file (volume_queries.cpp.in) compiles: the loops of the strategies that read a density
// (the ADB family) and the frame schedule (engine/typed_query.hpp). Internal to engine/.
#pragma once

#include "engine/typed_query.hpp"
#include "traversal/adb.hpp"
#include "traversal/coherent_adb.hpp"
#include "traversal/frame_schedule.hpp"
#include "traversal/wide_adb.hpp"
