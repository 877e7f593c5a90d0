# FindOpenCVModules: the OpenCV modules roughscope uses (core, imgproc, imgcodecs, photo), from
# Debian's per-module -dev packages. Debian ships OpenCV's CMake package (OpenCVConfig.cmake) and
# its pkg-config file only in libopencv-dev, which depends on every module (GUI, video, VTK, ...);
# this module finds the four libraries and the header folder directly instead.
#
# Defines OpenCVModules_FOUND, OpenCVModules_VERSION and the imported targets OpenCV::core,
# OpenCV::imgproc, OpenCV::imgcodecs and OpenCV::photo (each with its module dependencies).
find_path(OpenCVModules_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
set(_rs_opencv_modules core imgproc imgcodecs photo)
set(_rs_opencv_required OpenCVModules_INCLUDE_DIR)
foreach(_module IN LISTS _rs_opencv_modules)
  find_library(OpenCVModules_${_module}_LIBRARY NAMES opencv_${_module})
  list(APPEND _rs_opencv_required OpenCVModules_${_module}_LIBRARY)
  mark_as_advanced(OpenCVModules_${_module}_LIBRARY)
endforeach()
set(OpenCVModules_VERSION "")
if(OpenCVModules_INCLUDE_DIR AND EXISTS "${OpenCVModules_INCLUDE_DIR}/opencv2/core/version.hpp")
  file(STRINGS "${OpenCVModules_INCLUDE_DIR}/opencv2/core/version.hpp" _rs_cv_version
       REGEX "^#define CV_VERSION_(MAJOR|MINOR|REVISION)[ \t]+[0-9]+")
  foreach(_part MAJOR MINOR REVISION)
    string(REGEX REPLACE ".*CV_VERSION_${_part}[ \t]+([0-9]+).*" "\\1" _rs_cv_${_part} "${_rs_cv_version}")
  endforeach()
  set(OpenCVModules_VERSION "${_rs_cv_MAJOR}.${_rs_cv_MINOR}.${_rs_cv_REVISION}")
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCVModules
  REQUIRED_VARS ${_rs_opencv_required}
  VERSION_VAR OpenCVModules_VERSION)
if(OpenCVModules_FOUND)
  set(_rs_opencv_deps_core "")
  set(_rs_opencv_deps_imgproc OpenCV::core)
  set(_rs_opencv_deps_imgcodecs OpenCV::imgproc OpenCV::core)
  set(_rs_opencv_deps_photo OpenCV::imgproc OpenCV::core)
  foreach(_module IN LISTS _rs_opencv_modules)
    if(NOT TARGET OpenCV::${_module})
      add_library(OpenCV::${_module} UNKNOWN IMPORTED)
      set_target_properties(OpenCV::${_module} PROPERTIES
        IMPORTED_LOCATION "${OpenCVModules_${_module}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${OpenCVModules_INCLUDE_DIR}"
        INTERFACE_LINK_LIBRARIES "${_rs_opencv_deps_${_module}}")
    endif()
  endforeach()
endif()
mark_as_advanced(OpenCVModules_INCLUDE_DIR)
