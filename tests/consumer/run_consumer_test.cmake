# Installs the built ceres_sesync into a staging prefix, then configures,
# builds and runs the consumer project next to this file against it with
# find_package(ceres_sesync). Run by ctest as
#   cmake -DSOURCE_DIR=... -DBINARY_DIR=... -DBUILD_TYPE=... -P run_consumer_test.cmake
foreach(var SOURCE_DIR BINARY_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "consumer test: -D${var}=... is required")
  endif()
endforeach()
if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()

set(stage "${BINARY_DIR}/consumer_stage")
set(build "${BINARY_DIR}/consumer_build")
file(REMOVE_RECURSE "${stage}" "${build}")

# Use the parent build's compiler and dependency locations, so that a
# dependency found through a custom prefix is found again.
load_cache("${BINARY_DIR}" READ_WITH_PREFIX parent_
           CMAKE_CXX_COMPILER Ceres_DIR Eigen3_DIR glog_DIR gflags_DIR
           spectra_DIR)
set(forwarded "-DCMAKE_PREFIX_PATH=${stage}")
foreach(var CMAKE_CXX_COMPILER Ceres_DIR Eigen3_DIR glog_DIR gflags_DIR
            spectra_DIR)
  if(parent_${var})
    list(APPEND forwarded "-D${var}=${parent_${var}}")
  endif()
endforeach()

# Runs one step; any failure stops the test with the step's output.
function(run_step name)
  execute_process(COMMAND ${ARGN}
                  RESULT_VARIABLE result
                  OUTPUT_VARIABLE output
                  ERROR_VARIABLE output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "consumer test: ${name} failed (${result}):\n${output}")
  endif()
  message(STATUS "consumer test: ${name}: ok")
endfunction()

run_step(install
  "${CMAKE_COMMAND}" --install "${BINARY_DIR}" --prefix "${stage}"
  --config "${BUILD_TYPE}")
if(NOT EXISTS "${stage}/include/ceres_sesync/g2o_io.h")
  message(FATAL_ERROR "consumer test: headers were not installed in ${stage}")
endif()
run_step(configure
  "${CMAKE_COMMAND}" -S "${SOURCE_DIR}/tests/consumer" -B "${build}"
  "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}" ${forwarded})
run_step(build "${CMAKE_COMMAND}" --build "${build}" --config "${BUILD_TYPE}")
run_step(run "${build}/consumer")
