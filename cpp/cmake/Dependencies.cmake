# Every system dependency is found once here and wrapped in an ambfplus::dep_* target.
# Debian 12 provides all of them (see .ci/install-system-deps); nothing is downloaded at build time.

find_package(PkgConfig REQUIRED)

# Eigen: header-only maths.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
add_library(ambfplus_dep_eigen INTERFACE)
target_link_libraries(ambfplus_dep_eigen INTERFACE Eigen3::Eigen)
add_library(ambfplus::dep_eigen ALIAS ambfplus_dep_eigen)

# assimp: mesh files.
find_package(assimp REQUIRED)
add_library(ambfplus_dep_assimp INTERFACE)
target_link_libraries(ambfplus_dep_assimp INTERFACE assimp::assimp)
add_library(ambfplus::dep_assimp ALIAS ambfplus_dep_assimp)

# OpenCV: image files; only the modules the engine uses. Debian ships OpenCVConfig.cmake only in
# the all-modules libopencv-dev, so without it the per-module -dev packages are found directly.
set(_opencv_modules core imgproc imgcodecs)
add_library(ambfplus_dep_opencv INTERFACE)
find_package(OpenCV QUIET CONFIG COMPONENTS ${_opencv_modules})
if(OpenCV_FOUND)
  foreach(_m ${_opencv_modules})
    target_link_libraries(ambfplus_dep_opencv INTERFACE opencv_${_m})
  endforeach()
else()
  find_path(AMBFPLUS_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
  target_include_directories(ambfplus_dep_opencv INTERFACE ${AMBFPLUS_OPENCV_INCLUDE_DIR})
  foreach(_m ${_opencv_modules})
    find_library(AMBFPLUS_OPENCV_${_m}_LIBRARY opencv_${_m} REQUIRED)
    target_link_libraries(ambfplus_dep_opencv INTERFACE ${AMBFPLUS_OPENCV_${_m}_LIBRARY})
  endforeach()
  message(STATUS "OpenCV modules ${_opencv_modules} in ${AMBFPLUS_OPENCV_INCLUDE_DIR}")
endif()
add_library(ambfplus::dep_opencv ALIAS ambfplus_dep_opencv)

# OpenGL through EGL; libepoxy resolves GL and EGL entry points at run time.
find_package(OpenGL REQUIRED COMPONENTS EGL OpenGL)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
add_library(ambfplus_dep_gl INTERFACE)
target_link_libraries(ambfplus_dep_gl INTERFACE PkgConfig::EPOXY OpenGL::EGL OpenGL::OpenGL)
add_library(ambfplus::dep_gl ALIAS ambfplus_dep_gl)

# yaml-cpp: ADF scene files and label tables (0.7 exports the target `yaml-cpp`, no namespace).
find_package(yaml-cpp REQUIRED)
add_library(ambfplus_dep_yaml INTERFACE)
if(TARGET yaml-cpp::yaml-cpp)
  target_link_libraries(ambfplus_dep_yaml INTERFACE yaml-cpp::yaml-cpp)
else()
  target_link_libraries(ambfplus_dep_yaml INTERFACE yaml-cpp)
endif()
add_library(ambfplus::dep_yaml ALIAS ambfplus_dep_yaml)

# zlib: gzip-encoded NRRD volumes.
find_package(ZLIB REQUIRED)
add_library(ambfplus_dep_zlib INTERFACE)
target_link_libraries(ambfplus_dep_zlib INTERFACE ZLIB::ZLIB)
add_library(ambfplus::dep_zlib ALIAS ambfplus_dep_zlib)

find_package(Threads REQUIRED)
