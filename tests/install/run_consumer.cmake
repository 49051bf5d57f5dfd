# ctest -P script: install the build tree into a scratch prefix, then configure, build and run the consumer.
# Inputs: BUILD_DIR, SOURCE_DIR, WORK_DIR, GENERATOR, BUILD_TYPE, CXX_COMPILER, CXX_FLAGS, LINKER_FLAGS;
# with the Python module, PYTHON (the interpreter) and PYTHON_DIR (its install folder below the prefix).
file(REMOVE_RECURSE "${WORK_DIR}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/install/consumer" -B "${WORK_DIR}/build" -G "${GENERATOR}"
    -DCMAKE_BUILD_TYPE=${BUILD_TYPE} "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
    "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}"
    "-DBVHLAB_EXAMPLE=${SOURCE_DIR}/bench/examples/collide.cpp")
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer")
run("${WORK_DIR}/build/consumer_load")
set(pinion "${SOURCE_DIR}/meshes/pinion.off")
run("${WORK_DIR}/build/example_collide" "${pinion}" "${pinion}" 0.01 0 0)
message(STATUS "consumer and the shipped example built against ${WORK_DIR}/prefix and ran")
# The CLI is installed beside the libraries, and runs from the prefix.
if(NOT EXISTS "${WORK_DIR}/prefix/bin/bvhlab")
  message(FATAL_ERROR "cmake --install put no bvhlab CLI in ${WORK_DIR}/prefix/bin")
endif()
execute_process(COMMAND "${WORK_DIR}/prefix/bin/bvhlab" info "${pinion}" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "triangles")
  message(FATAL_ERROR "the installed CLI failed (${rc}): ${out}\n${err}")
endif()
message(STATUS "the installed CLI ran")
if(PYTHON)
  set(site "${WORK_DIR}/prefix/${PYTHON_DIR}")
  file(GLOB module "${site}/bvhlab*.so")
  if(NOT module)
    message(FATAL_ERROR "the Python module is not installed in ${site}")
  endif()
  run(${CMAKE_COMMAND} -E env "PYTHONPATH=${site}" ${PYTHON} -c [=[
import sys, bvhlab
assert bvhlab.__file__.startswith(sys.argv[1]), bvhlab.__file__
tree = bvhlab.Tree(bvhlab.load_mesh(sys.argv[2], normalize=True))
assert bvhlab.query(tree, tree, translation=[0.5, 0, 0]).collides
assert not bvhlab.query(tree, tree, translation=[3, 0, 0]).collides
]=] "${site}" "${SOURCE_DIR}/meshes/pinion.off")
  message(STATUS "the Python module imported from ${site} and ran")
endif()
