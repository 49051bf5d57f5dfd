# Fails naming the first of FILES that includes bench/core/registry.hpp. The bench sources that are compiled
# once and linked into both registries' builds (bench/CMakeLists.txt) must not read the registry, or one
# registry's code would end up in the other build. Run at configure time and as the ctest
# `bench_shared_sources_skip_the_registry`, so an include added later fails the tests without reconfiguring.
#   cmake -DFILES="a.cpp;b.hpp" -P cmake/CheckRegistryIncludes.cmake
function(bvhlab_check_registry_includes files)
  foreach(file ${files})
    file(STRINGS ${file} registry_include REGEX "#include \"bench/core/registry\\.hpp\"")
    if(registry_include)
      message(FATAL_ERROR "${file} includes bench/core/registry.hpp: list it with the registry sources")
    endif()
  endforeach()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED FILES)
  bvhlab_check_registry_includes("${FILES}")
endif()
