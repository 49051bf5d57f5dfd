// The headers most test files include, precompiled once for all of them (tests/CMakeLists.txt,
// bvhlab_test_pch): parsing them took about 5 s of each test file's 10 to 15 s. Only headers that no build
// option or registry macro changes belong here, and no heavy third-party ones a few tests use (CGAL).
#pragma once

#include "bench/core/generators.hpp"
#include "bvh/bvh.hpp"
#include "bvh/mesh_io.hpp"
#include "traversal/adb.hpp"
#include "traversal/exact.hpp"
#include "volumes/shipped.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>
