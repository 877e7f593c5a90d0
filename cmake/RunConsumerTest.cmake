# Downstream-consumer test, run by ctest as `cmake -D... -P RunConsumerTest.cmake`.
#
# 1. installs the already-built project into <binary dir>/consumer-prefix,
# 2. configures and builds tests/consumer against that prefix with
#    find_package(roughscope REQUIRED),
# 3. checks the package was found in that prefix (not somewhere else),
# 4. runs the consumer and checks it printed the expected version.
#
# Inputs (-D): RS_BINARY_DIR, RS_CONSUMER_SOURCE_DIR, RS_GENERATOR,
# RS_MAKE_PROGRAM, RS_BUILD_TYPE, RS_CXX_COMPILER, RS_CXX_FLAGS,
# RS_LINKER_FLAGS, RS_PREFIX_PATH ("|"-separated), RS_EXPECTED_VERSION.

cmake_minimum_required(VERSION 3.25)

foreach(var RS_BINARY_DIR RS_CONSUMER_SOURCE_DIR RS_GENERATOR RS_EXPECTED_VERSION)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "RunConsumerTest.cmake: ${var} is not set")
  endif()
endforeach()

set(prefix "${RS_BINARY_DIR}/consumer-prefix")
set(build "${RS_BINARY_DIR}/consumer-build")
file(REMOVE_RECURSE "${prefix}" "${build}")

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc COMMAND_ECHO STDOUT)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer test: ${step} failed (exit ${rc})")
  endif()
endfunction()

# --- 1. install -------------------------------------------------------------
set(config_args "")
if(RS_BUILD_TYPE)
  set(config_args --config "${RS_BUILD_TYPE}")
endif()
run("install" "${CMAKE_COMMAND}" --install "${RS_BINARY_DIR}" --prefix "${prefix}" ${config_args})

foreach(f
    "include/roughscope/version.hpp"
    "include/roughscope/scattering/geometry.hpp"
    "include/roughscope/scattering/reflectance_models.hpp"
    "include/roughscope/roughscope.hpp")
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "consumer test: ${f} was not installed into ${prefix}")
  endif()
endforeach()

# --- 2. configure + build the consumer ---------------------------------------
string(REPLACE "|" ";" prefix_path "${RS_PREFIX_PATH}")
list(PREPEND prefix_path "${prefix}")
string(REPLACE ";" "\\;" prefix_path_arg "${prefix_path}")

set(configure_args
  -S "${RS_CONSUMER_SOURCE_DIR}" -B "${build}" -G "${RS_GENERATOR}"
  "-DCMAKE_PREFIX_PATH=${prefix_path_arg}"
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
  -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF)
if(RS_MAKE_PROGRAM)
  list(APPEND configure_args "-DCMAKE_MAKE_PROGRAM=${RS_MAKE_PROGRAM}")
endif()
if(RS_BUILD_TYPE)
  list(APPEND configure_args "-DCMAKE_BUILD_TYPE=${RS_BUILD_TYPE}")
endif()
if(RS_CXX_COMPILER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${RS_CXX_COMPILER}")
endif()
if(RS_CXX_FLAGS)
  list(APPEND configure_args "-DCMAKE_CXX_FLAGS=${RS_CXX_FLAGS}")
endif()
if(RS_LINKER_FLAGS)
  list(APPEND configure_args "-DCMAKE_EXE_LINKER_FLAGS=${RS_LINKER_FLAGS}")
endif()
run("configure" "${CMAKE_COMMAND}" ${configure_args})

# --- 3. the package must come from the prefix we just installed --------------
file(STRINGS "${build}/CMakeCache.txt" found_dir REGEX "^roughscope_DIR:")
string(REGEX REPLACE "^roughscope_DIR:[A-Z]+=" "" found_dir "${found_dir}")
file(REAL_PATH "${prefix}" real_prefix)
file(REAL_PATH "${found_dir}" real_found_dir)
string(FIND "${real_found_dir}/" "${real_prefix}/" pos)
if(NOT pos EQUAL 0)
  message(FATAL_ERROR
    "consumer test: find_package(roughscope) used '${found_dir}', "
    "not the freshly installed prefix '${prefix}'")
endif()

run("build" "${CMAKE_COMMAND}" --build "${build}" ${config_args})

# --- 3b. the photograph topic alone links neither Ceres nor the fit/brdf/objects topics --------
# The link command of roughscope_consumer_photo, from the generator's files (Ninja: build.ninja's
# LINK_LIBRARIES of its link step; Makefiles: the target's link.txt).
set(photo_link "")
if(EXISTS "${build}/build.ninja")
  file(READ "${build}/build.ninja" ninja)
  string(FIND "${ninja}" "build roughscope_consumer_photo:" start)
  if(NOT start EQUAL -1)
    string(SUBSTRING "${ninja}" ${start} -1 ninja)
    string(REGEX MATCH "LINK_LIBRARIES = [^\n]*" photo_link "${ninja}")
  endif()
elseif(EXISTS "${build}/CMakeFiles/roughscope_consumer_photo.dir/link.txt")
  file(READ "${build}/CMakeFiles/roughscope_consumer_photo.dir/link.txt" photo_link)
endif()
if(NOT photo_link MATCHES "roughscope_photo")
  message(FATAL_ERROR "consumer test: the link command of roughscope_consumer_photo was not found")
endif()
foreach(forbidden "ceres" "roughscope_fit" "roughscope_brdf" "roughscope_objects" "roughscope_measure")
  string(FIND "${photo_link}" "${forbidden}" pos)
  if(NOT pos EQUAL -1)
    message(FATAL_ERROR "consumer test: roughscope::photo alone links ${forbidden}:\n${photo_link}")
  endif()
endforeach()

# --- 4. run them: the umbrella target and one topic alone ---------------------
foreach(name roughscope_consumer roughscope_consumer_scattering roughscope_consumer_photo)
  set(exe "")
  foreach(candidate
      "${build}/${name}"
      "${build}/${RS_BUILD_TYPE}/${name}"
      "${build}/${name}.exe"
      "${build}/${RS_BUILD_TYPE}/${name}.exe")
    if(EXISTS "${candidate}" AND NOT IS_DIRECTORY "${candidate}")
      set(exe "${candidate}")
      break()
    endif()
  endforeach()
  if(NOT exe)
    message(FATAL_ERROR "consumer test: built consumer executable ${name} not found in ${build}")
  endif()

  execute_process(COMMAND "${exe}"
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer test: ${exe} exited with ${rc}")
  endif()
  string(FIND "${out}" "${RS_EXPECTED_VERSION}" pos)
  if(pos EQUAL -1)
    message(FATAL_ERROR
      "consumer test: output of ${name} does not contain version '${RS_EXPECTED_VERSION}'")
  endif()
endforeach()
