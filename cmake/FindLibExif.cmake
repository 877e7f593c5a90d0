# FindLibExif: the libexif EXIF parser (Debian's libexif-dev ships a pkg-config file, no CMake
# package).
#
# Defines LibExif_FOUND, LibExif_VERSION and the imported target LibExif::LibExif (header
# libexif/exif-data.h, library exif).
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(PC_LIBEXIF QUIET libexif)
endif()
find_path(LibExif_INCLUDE_DIR libexif/exif-data.h HINTS ${PC_LIBEXIF_INCLUDEDIR} ${PC_LIBEXIF_INCLUDE_DIRS})
find_library(LibExif_LIBRARY NAMES exif HINTS ${PC_LIBEXIF_LIBDIR} ${PC_LIBEXIF_LIBRARY_DIRS})
set(LibExif_VERSION "${PC_LIBEXIF_VERSION}")
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LibExif
  REQUIRED_VARS LibExif_LIBRARY LibExif_INCLUDE_DIR
  VERSION_VAR LibExif_VERSION)
if(LibExif_FOUND AND NOT TARGET LibExif::LibExif)
  add_library(LibExif::LibExif UNKNOWN IMPORTED)
  set_target_properties(LibExif::LibExif PROPERTIES
    IMPORTED_LOCATION "${LibExif_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LibExif_INCLUDE_DIR}")
endif()
mark_as_advanced(LibExif_INCLUDE_DIR LibExif_LIBRARY)
