# Installs the build into WORK_DIR/prefix, then configures, builds and runs the consumer with
# find_package(kin2grf) from there (the test package.find_package).
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
# The README's CMake snippet, verbatim: the ```cmake block that calls find_package(kin2grf.
file(READ ${SOURCE_DIR}/../../README.md readme)
string(REGEX MATCH "```cmake\n(find_package\\(kin2grf[^`]*)```" block "${readme}")
if(NOT CMAKE_MATCH_1)
  message(FATAL_ERROR "README.md has no ```cmake block with find_package(kin2grf ...)")
endif()
file(WRITE ${WORK_DIR}/readme_snippet.cmake "${CMAKE_MATCH_1}")
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
    -DREADME_SNIPPET=${WORK_DIR}/readme_snippet.cmake)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/my_tool)
# The Python package is installed too (when the build made it).
if(EXISTS ${BUILD_DIR}/python/kin2grf/__init__.py AND NOT EXISTS ${WORK_DIR}/prefix/lib/python3/dist-packages/kin2grf/__init__.py)
  message(FATAL_ERROR "the Python package was not installed")
endif()
