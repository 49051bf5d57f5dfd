# Where a template's code is compiled: fails when one of OBJECTS defines a symbol whose demangled name matches
# PATTERN, or when none of OWNERS does (so that a renamed symbol cannot make the check pass unseen). The
# engine's tests run it on its objects (tests/engine/CMakeLists.txt): code compiled once stays so.
#   cmake -DNM=llvm-nm -DOBJECTS="a.o|b.o" -DOWNERS="c.o|d.o" -DPATTERN="regex" -P cmake/CheckObjectSymbols.cmake
foreach(var NM OBJECTS OWNERS PATTERN)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "CheckObjectSymbols.cmake needs -D${var}=...")
  endif()
endforeach()

# The defined symbols of `objects` ('|'-separated), demangled, one per line, in `out`.
function(defined_symbols objects out)
  string(REPLACE "|" ";" objects "${objects}")
  list(FILTER objects INCLUDE REGEX "\\.o(bj)?$")  # not a target's precompiled header
  execute_process(COMMAND ${NM} -C --defined-only ${objects} OUTPUT_VARIABLE symbols RESULT_VARIABLE failed)
  if(failed)
    message(FATAL_ERROR "${NM} failed on ${objects}")
  endif()
  set(${out} "${symbols}" PARENT_SCOPE)
endfunction()

defined_symbols("${OWNERS}" owned)
if(NOT owned MATCHES "${PATTERN}")
  message(FATAL_ERROR "no owner object defines a symbol matching '${PATTERN}': the check has nothing to check")
endif()
defined_symbols("${OBJECTS}" symbols)
string(REGEX MATCH "[^\n]*${PATTERN}[^\n]*" found "${symbols}")
if(found)
  message(FATAL_ERROR "an object that must leave it to its owners defines: ${found}")
endif()
