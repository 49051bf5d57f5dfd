# Shared helpers: one warning set, one way to declare a library folder and a test.
include_guard(GLOBAL)

add_library(bvhlab_warnings INTERFACE)
target_compile_options(bvhlab_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wno-unused-parameter>)

# The source tree's root is the include root: #include "volumes/aabb.hpp".
# Installed headers keep the same relative paths under include/bvhlab.
function(bvhlab_folder_includes target scope)
  target_include_directories(${target} ${scope}
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:include/bvhlab>)
endfunction()

# bvhlab_add_test(NAME name SOURCES a.cpp ... [LIBS ...] [LABELS ...] [TIMEOUT s])
# One GoogleTest executable; each TEST is a separate ctest entry so ctest -j spreads them.
function(bvhlab_add_test)
  cmake_parse_arguments(T "" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main bvhlab_warnings)
  target_include_directories(${T_NAME} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 600)
  endif()
  gtest_discover_tests(${T_NAME}
    PROPERTIES LABELS "unit;${T_LABELS}" TIMEOUT ${T_TIMEOUT}
               ENVIRONMENT "BVHLAB_SOURCE_DIR=${PROJECT_SOURCE_DIR};BVHLAB_MESH_CACHE=${BVHLAB_MESH_CACHE}"
    DISCOVERY_TIMEOUT 60)
endfunction()
