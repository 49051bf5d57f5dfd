# Shared helpers: one warning set, one way to declare a library folder and a test.
include_guard(GLOBAL)

add_library(bvhlab_warnings INTERFACE)
target_compile_options(bvhlab_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wno-unused-parameter>)
if(BVHLAB_WERROR)
  # GCC 12 reports an impossible memcpy overlap inside std::string's operator+ (-Wrestrict, a known false
  # positive, in bench/core/scene.cpp and bench/deform/report.cpp): that one stays a warning.
  target_compile_options(bvhlab_warnings INTERFACE $<$<CXX_COMPILER_ID:GNU,Clang>:-Werror>
    $<$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>:-Wno-error=restrict>)
endif()

# bvhlab_unity(target batch): with BVHLAB_UNITY_BUILD, target's sources are compiled `batch` to a translation
# unit, in the order they are listed (CMake's unity build); a file with compile options of its own is compiled
# alone. The files of a unit share one anonymous namespace, so names there must not repeat within a target.
# The batch keeps every unit near 20 s on this project's 2-core machine. OFF compiles each file alone, which
# also checks that each includes what it uses.
function(bvhlab_unity target batch)
  if(BVHLAB_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${batch})
  endif()
endfunction()

# bvhlab_cold(target ...): code that nothing times (parsing, printing, reports, the Python module's glue, the
# tests' own code: tests/CMakeLists.txt) is compiled at -O1 in Release: it compiles in about 60 % of the
# time. The libraries it calls, where every timed query runs (engine/, traversal/), keep -O3.
set(BVHLAB_COLD_OPTIONS $<$<CONFIG:Release>:-O1>)
function(bvhlab_cold)
  foreach(target ${ARGN})
    target_compile_options(${target} PRIVATE ${BVHLAB_COLD_OPTIONS})
  endforeach()
endfunction()

# bvhlab_glue(target ...): code that only reads arguments and calls the libraries (the CLI's commands) is
# compiled at -O0 in Release: it does no work of its own worth optimising, and compiles in about 60 % of the
# time it takes at -O1.
function(bvhlab_glue)
  foreach(target ${ARGN})
    target_compile_options(${target} PRIVATE $<$<CONFIG:Release>:-O0>)
  endforeach()
endfunction()

# In the build, the source tree's root is the include root: #include "volumes/aabb.hpp". Installed, the
# headers sit under include/bvhlab and users write #include <bvhlab/volumes/aabb.hpp>, which cannot clash
# with another project's volumes/ or adb/; the library's headers include each other by relative paths
# ("../bvh/bvh.hpp"), which hold in both layouts. The build offers the installed spelling too (through
# <build>/include/bvhlab, a link to the source tree), so code written against the package, such as the
# shipped example, compiles unchanged in the build and against an install.
file(MAKE_DIRECTORY "${PROJECT_BINARY_DIR}/include")
file(CREATE_LINK "${PROJECT_SOURCE_DIR}" "${PROJECT_BINARY_DIR}/include/bvhlab" SYMBOLIC)
function(bvhlab_folder_includes target scope)
  target_include_directories(${target} ${scope}
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/include>
    $<INSTALL_INTERFACE:include>)
endfunction()

# bvhlab_add_test(NAME name SOURCES a.cpp ... [LIBS ...] [LABELS ...] [TIMEOUT s] [NEEDS_MESHES] [SANITIZED]
#                 [ONE_PROCESS] [UNITY n])
# One GoogleTest executable; each TEST is a separate ctest entry so ctest -j spreads them.
# UNITY n: its sources compiled n to a unit (bvhlab_unity): test files that build the same kinds of trees
# share their instantiation.
# ONE_PROCESS: the tests share a setup that costs more than they do (a static fixture built once per process,
# such as annotated trees): ctest runs the executable once, as one entry named after it.
# NEEDS_MESHES: the tests read fetched meshes, so they require the ctest fixture `meshes` (cmake/Meshes.cmake).
# SANITIZED: the ASan stage builds and runs it too (label `sanitized`, target bvhlab_sanitized_tests; which
# tests and why: tests/README.md, "Sanitizers and fuzzing"). Every test runs in the Release stage.
# BVHLAB_TEST_SHARDS n (the sanitizer presets): each executable is n ctest entries <name>/shard_<k>, each
# running every n-th test (GoogleTest's own sharding) in one process, instead of a process per test: an
# instrumented process takes 0.1 to 0.2 s to start and exit, a fifth of the ASan stage's test time. The
# asan preset's GTEST_FILTER leaves tests out by name (tests/README.md, "Sanitizers and fuzzing").
function(bvhlab_add_test)
  cmake_parse_arguments(T "NEEDS_MESHES;SANITIZED;ONE_PROCESS" "NAME;TIMEOUT;UNITY" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${T_NAME} ${T_SOURCES})
  if(T_UNITY)
    bvhlab_unity(${T_NAME} ${T_UNITY})
  endif()
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main bvhlab_warnings)
  target_include_directories(${T_NAME} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_precompile_headers(${T_NAME} REUSE_FROM bvhlab_test_pch)  # tests/CMakeLists.txt
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 600)
  endif()
  set(shards 0)
  if(NOT T_ONE_PROCESS AND BVHLAB_TEST_SHARDS GREATER 0)
    set(shards ${BVHLAB_TEST_SHARDS})
  endif()
  if(T_ONE_PROCESS)
    add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  elseif(shards)
    math(EXPR last_shard "${shards} - 1")
    foreach(k RANGE ${last_shard})
      add_test(NAME ${T_NAME}/shard_${k} COMMAND ${T_NAME})
    endforeach()
  else()
    gtest_discover_tests(${T_NAME} DISCOVERY_TIMEOUT 60)
  endif()
  # The properties go into a script ctest includes after the discovered tests, not into
  # gtest_discover_tests(PROPERTIES): that flattens list values ("unit;bvh", two ENVIRONMENT entries) into the
  # name/value pairs, so labels, timeout and environment were silently lost.
  if(T_SANITIZED)
    list(APPEND T_LABELS sanitized)
    add_dependencies(bvhlab_sanitized_tests ${T_NAME})
  endif()
  string(JOIN ";" labels unit ${T_LABELS})
  set(properties "LABELS [==[${labels}]==] TIMEOUT ${T_TIMEOUT} ENVIRONMENT [==[BVHLAB_SOURCE_DIR=")
  string(APPEND properties "${PROJECT_SOURCE_DIR};BVHLAB_MESH_CACHE=${BVHLAB_MESH_CACHE}]==]")
  if(T_NEEDS_MESHES)
    string(APPEND properties " FIXTURES_REQUIRED meshes")
  endif()
  if(T_ONE_PROCESS)
    # A whole executable in one entry: ctest starts it among the first (see tests/python/CMakeLists.txt).
    cmake_language(EVAL CODE "set_tests_properties(${T_NAME} PROPERTIES ${properties} COST 30)")
    return()
  endif()
  if(shards)
    foreach(k RANGE ${last_shard})
      cmake_language(EVAL CODE "set_tests_properties(${T_NAME}/shard_${k} PROPERTIES ${properties} COST 10)")
      set_property(TEST ${T_NAME}/shard_${k} APPEND PROPERTY ENVIRONMENT GTEST_TOTAL_SHARDS=${shards}
                                                                      GTEST_SHARD_INDEX=${k})
    endforeach()
    return()
  endif()
  set(script "${CMAKE_CURRENT_BINARY_DIR}/${T_NAME}_properties.cmake")
  file(WRITE "${script}"
       "if(NOT \"\${${T_NAME}_TESTS}\" STREQUAL \"\")\n"
       "  set_tests_properties(\${${T_NAME}_TESTS} PROPERTIES ${properties})\n"
       "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${script}")
endfunction()

# bvhlab_add_benchmark_test(NAME name BENCHMARK bench_x ARGS ...): a ctest entry that runs a benchmark suite;
# `make test` builds the suites such tests run and leaves the others to `make build` (bvhlab_tests below).
function(bvhlab_add_benchmark_test)
  cmake_parse_arguments(T "" "NAME;BENCHMARK" "ARGS" ${ARGN})
  add_test(NAME ${T_NAME} COMMAND ${T_BENCHMARK} ${T_ARGS})
  set_property(GLOBAL APPEND PROPERTY BVHLAB_TESTED_BENCHMARKS ${T_BENCHMARK})
endfunction()

# Every target defined in `dir` and below it.
function(bvhlab_targets_below dir out)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub ${subdirs})
    bvhlab_targets_below(${sub} more)
    list(APPEND targets ${more})
  endforeach()
  set(${out} ${targets} PARENT_SCOPE)
endfunction()

# The target `make test` builds: everything the default build makes but the benchmark suites no test runs,
# which only compile there (`.ci/run` builds them in a stage of their own).
function(bvhlab_add_tests_target)
  bvhlab_targets_below(${PROJECT_SOURCE_DIR} targets)
  get_property(benchmarks GLOBAL PROPERTY BVHLAB_BENCHMARKS)
  get_property(tested GLOBAL PROPERTY BVHLAB_TESTED_BENCHMARKS)
  set(untested ${benchmarks})
  if(tested)
    list(REMOVE_ITEM untested ${tested})
  endif()
  add_custom_target(bvhlab_tests)
  foreach(target ${targets})
    get_target_property(type ${target} TYPE)
    get_target_property(excluded ${target} EXCLUDE_FROM_ALL)
    if(type STREQUAL "UTILITY" OR type STREQUAL "INTERFACE_LIBRARY" OR excluded OR target IN_LIST untested)
      continue()
    endif()
    add_dependencies(bvhlab_tests ${target})
  endforeach()
endfunction()
