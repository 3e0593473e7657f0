# The house's layering rule, checked by ctest (cmake -DSOURCE_DIR=... -P check_layers.cmake):
#  - the core (what kin2grf_core builds: markers -> landmarks -> model -> kinematics -> contact and
#    inverse dynamics, pipeline.hpp, trial.hpp) includes no file format, output, validation,
#    workflow or synthetic-data header, and no JSON or command-line library;
#  - a file format (io/) includes no dynamics, kinematics or pipeline header: it converts between
#    files and the core's data types (trial.hpp, model/), and does not know the method.
set(core_dirs dynamics kinematics markers model)
set(bad_for_core "kin2grf/(io|output|validation|workflow|synth)/|nlohmann/|CLI/")
set(bad_for_io "kin2grf/(dynamics|kinematics)/|kin2grf/pipeline\\.hpp")
set(failures "")
function(check_files pattern bad)
  file(GLOB_RECURSE files ${pattern})
  foreach(f IN LISTS files)
    file(STRINGS "${f}" lines REGEX "^#include")
    foreach(l IN LISTS lines)
      if(l MATCHES "${bad}")
        string(APPEND failures "\n  ${f}: ${l}")
      endif()
    endforeach()
  endforeach()
  set(failures "${failures}" PARENT_SCOPE)
endfunction()
foreach(d IN LISTS core_dirs)
  check_files("${SOURCE_DIR}/src/${d}/*.cpp" "${bad_for_core}")
  check_files("${SOURCE_DIR}/include/kin2grf/${d}/*.hpp" "${bad_for_core}")
endforeach()
foreach(f src/pipeline.cpp src/trial.cpp src/parallel.cpp src/option_table.cpp include/kin2grf/pipeline.hpp include/kin2grf/trial.hpp
                 include/kin2grf/option_table.hpp)
  check_files("${SOURCE_DIR}/${f}" "${bad_for_core}")
endforeach()
check_files("${SOURCE_DIR}/src/io/*.cpp" "${bad_for_io}")
check_files("${SOURCE_DIR}/include/kin2grf/io/*.hpp" "${bad_for_io}")
if(failures)
  message(FATAL_ERROR "layering: these includes cross the house's layers (docs/ARCHITECTURE.md):${failures}")
endif()
message(STATUS "layering: the core includes no format, and no format includes the method")
