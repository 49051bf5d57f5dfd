# Fails naming the first of FILES that includes the registry (engine/registry.hpp, or engine/typed_tree.hpp or
# typed_query.hpp, which instantiate it). The sources compiled once and linked into both registries' builds
# (bench/, the CLI) must not read it, or one registry's code would end up in the other build: they reach the
# policies through the run-time layer's handle (engine/any_tree.hpp). Run at configure time and as the ctest
# `bench_shared_sources_skip_the_registry`, so an include added later fails the tests without reconfiguring.
#   cmake -DFILES="a.cpp;b.hpp" -P cmake/CheckRegistryIncludes.cmake
function(bvhlab_check_registry_includes files)
  foreach(file ${files})
    file(STRINGS ${file} registry_include REGEX "#include \"engine/(registry|typed_tree|typed_query)\\.hpp\"")
    if(registry_include)
      message(FATAL_ERROR "${file} includes the registry: reach the policies through engine/any_tree.hpp, "
                          "or list it with the registry sources")
    endif()
  endforeach()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED FILES)
  bvhlab_check_registry_includes("${FILES}")
endif()
