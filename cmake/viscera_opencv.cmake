# OpenCV core/imgproc/imgcodecs -> opencv_core, opencv_imgproc, opencv_imgcodecs.  Authoring only.
# Debian ships OpenCVConfig.cmake in libopencv-dev alone, which pulls in every OpenCV module (video,
# highgui, contrib, ...). With only the three -dev packages of scripts/install-deps.sh there is no
# config file, so the recipe makes the same imported targets from the headers and libraries.
find_package(OpenCV 4 QUIET COMPONENTS core imgproc imgcodecs)
if(NOT OpenCV_FOUND AND NOT TARGET opencv_core)
  find_path(VISCERA_OPENCV_INCLUDE_DIR opencv2/core/version.hpp PATH_SUFFIXES opencv4 REQUIRED)
  file(STRINGS "${VISCERA_OPENCV_INCLUDE_DIR}/opencv2/core/version.hpp" major REGEX "#define CV_VERSION_MAJOR")
  if(NOT major MATCHES "CV_VERSION_MAJOR[ \t]+4")
    message(FATAL_ERROR "OpenCV 4 is required (${VISCERA_OPENCV_INCLUDE_DIR}: ${major})")
  endif()
  set(deps "")
  foreach(module core imgproc imgcodecs)
    find_library(VISCERA_OPENCV_${module}_LIBRARY opencv_${module} REQUIRED)
    add_library(opencv_${module} UNKNOWN IMPORTED GLOBAL)
    set_target_properties(opencv_${module} PROPERTIES
      IMPORTED_LOCATION "${VISCERA_OPENCV_${module}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${VISCERA_OPENCV_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES "${deps}")
    list(APPEND deps opencv_${module})
  endforeach()
  message(STATUS "OpenCV 4 (no OpenCVConfig.cmake): ${VISCERA_OPENCV_INCLUDE_DIR}")
endif()
