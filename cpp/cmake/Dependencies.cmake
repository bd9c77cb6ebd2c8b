# Every system dependency is found once here and wrapped in an ambfplus::dep_* target.
# Debian 12 provides all of them (see .ci/install-system-deps); nothing is downloaded at build time.

find_package(PkgConfig REQUIRED)

# Eigen: header-only maths.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
add_library(ambfplus_dep_eigen INTERFACE)
target_link_libraries(ambfplus_dep_eigen INTERFACE Eigen3::Eigen)
add_library(ambfplus::dep_eigen ALIAS ambfplus_dep_eigen)
# Its licence travels with the headers the package installs (Debian's copyright file).
find_file(AMBFPLUS_EIGEN_LICENSE copyright PATHS /usr/share/doc/libeigen3-dev NO_DEFAULT_PATH)
if(SKBUILD AND NOT AMBFPLUS_EIGEN_LICENSE)
  message(WARNING "Eigen's licence file (Debian: /usr/share/doc/libeigen3-dev/copyright) not "
    "found: the package installs Eigen's headers without it")
endif()

# assimp: mesh files.
find_package(assimp REQUIRED)
add_library(ambfplus_dep_assimp INTERFACE)
target_link_libraries(ambfplus_dep_assimp INTERFACE assimp::assimp)
add_library(ambfplus::dep_assimp ALIAS ambfplus_dep_assimp)

# libpng and libjpeg(-turbo): image files (PNG, JPEG), read and written directly, permissively
# licensed and without the codecs, geodata and video libraries a general image library brings.
find_package(PNG REQUIRED)
find_package(JPEG REQUIRED)
add_library(ambfplus_dep_image INTERFACE)
target_link_libraries(ambfplus_dep_image INTERFACE PNG::PNG JPEG::JPEG)
add_library(ambfplus::dep_image ALIAS ambfplus_dep_image)

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

# Bullet: rigid and soft body physics. Debian's BulletConfig.cmake carries relative paths, so
# pkg-config it is (`bullet`: the single-precision build). Float and double builds mangle
# differently, so a link test catches headers and libraries that disagree at configure time.
pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet)
add_library(ambfplus_dep_bullet INTERFACE)
target_link_libraries(ambfplus_dep_bullet INTERFACE PkgConfig::BULLET)
add_library(ambfplus::dep_bullet ALIAS ambfplus_dep_bullet)
include(CheckCXXSourceCompiles)
set(CMAKE_REQUIRED_INCLUDES ${BULLET_INCLUDE_DIRS})
set(CMAKE_REQUIRED_LIBRARIES PkgConfig::BULLET)
check_cxx_source_compiles([=[
#include <btBulletDynamicsCommon.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
int main() {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, 0, -9.8));
  return world.stepSimulation(0.001, 1, 0.001) == 1 ? 0 : 1;
}]=] AMBFPLUS_BULLET_LINKS)
unset(CMAKE_REQUIRED_INCLUDES)
unset(CMAKE_REQUIRED_LIBRARIES)
if(NOT AMBFPLUS_BULLET_LINKS)
  message(FATAL_ERROR "Bullet's headers and libraries do not link together (a double-precision "
    "build where the single-precision one is expected?). Install libbullet-dev (Debian).")
endif()

find_package(Threads REQUIRED)

# OpenXR: optional. Only its headers are needed at build time (libopenxr-dev); the Khronos loader
# is opened at run time, so a machine without one still runs everything else.
find_path(AMBFPLUS_OPENXR_INCLUDE_DIR openxr/openxr_platform.h)
add_library(ambfplus_dep_openxr INTERFACE)
if(AMBFPLUS_OPENXR_INCLUDE_DIR)
  target_include_directories(ambfplus_dep_openxr INTERFACE ${AMBFPLUS_OPENXR_INCLUDE_DIR})
  target_compile_definitions(ambfplus_dep_openxr INTERFACE AMBFPLUS_WITH_OPENXR=1)
  message(STATUS "OpenXR headers in ${AMBFPLUS_OPENXR_INCLUDE_DIR}: OpenXR sessions built")
else()
  message(STATUS "OpenXR headers not found (libopenxr-dev): OpenXR sessions not built")
endif()
add_library(ambfplus::dep_openxr ALIAS ambfplus_dep_openxr)

# miniaudio 0.11.25 (cpp/third_party/miniaudio/README.md says why this library): one header, not
# packaged by Debian 12 and not kept in this repository. Taken at configure time from the source
# distribution of the `miniaudio` package on PyPI (version 1.71), checked against the archive's
# and the header's SHA-256, and kept in the build tree, so a rebuild downloads nothing. Offline,
# point AMBFPLUS_MINIAUDIO_HEADER at a copy of that header (the same hash is checked).
set(AMBFPLUS_MINIAUDIO_HEADER "" CACHE FILEPATH
  "miniaudio.h 0.11.25 to use instead of downloading it from PyPI")
set(_ma_url "https://files.pythonhosted.org/packages/d8/d5/e5439dc08561f73656bfeb3340fc64ab63163e101426593d8fb9a025ff1e/miniaudio-1.71.tar.gz")
set(_ma_archive_sha256 ff51e2887bb673e2e757752b586b3dc924d59aa5fbcae9bbc45f4a111bd3262b)
set(_ma_header_sha256 ac7af4de748b7e26b777f37e01cee313a308a7296a3eb080e2906b320cc55c89)
set(AMBFPLUS_MINIAUDIO_INCLUDE_DIR ${CMAKE_BINARY_DIR}/third_party)
set(_ma_header ${AMBFPLUS_MINIAUDIO_INCLUDE_DIR}/miniaudio/miniaudio.h)

function(_ambfplus_check_miniaudio path out_ok)
  set(${out_ok} FALSE PARENT_SCOPE)
  if(EXISTS "${path}")
    file(SHA256 "${path}" hash)
    if(hash STREQUAL "${_ma_header_sha256}")
      set(${out_ok} TRUE PARENT_SCOPE)
    endif()
  endif()
endfunction()

_ambfplus_check_miniaudio("${_ma_header}" _ma_ok)
if(NOT _ma_ok AND AMBFPLUS_MINIAUDIO_HEADER)
  _ambfplus_check_miniaudio("${AMBFPLUS_MINIAUDIO_HEADER}" _ma_given_ok)
  if(NOT _ma_given_ok)
    message(FATAL_ERROR "AMBFPLUS_MINIAUDIO_HEADER=${AMBFPLUS_MINIAUDIO_HEADER}: not miniaudio.h "
      "0.11.25 (expected SHA-256 ${_ma_header_sha256}: the file miniaudio/miniaudio.h of "
      "${_ma_url})")
  endif()
  configure_file("${AMBFPLUS_MINIAUDIO_HEADER}" "${_ma_header}" COPYONLY)
elseif(NOT _ma_ok)
  set(_ma_archive ${CMAKE_BINARY_DIR}/_downloads/miniaudio-1.71.tar.gz)
  message(STATUS "Downloading miniaudio 0.11.25 (PyPI miniaudio 1.71 source distribution)")
  file(DOWNLOAD "${_ma_url}" "${_ma_archive}" EXPECTED_HASH SHA256=${_ma_archive_sha256}
    TLS_VERIFY ON STATUS _ma_status)
  list(GET _ma_status 0 _ma_code)
  if(NOT _ma_code EQUAL 0)
    list(GET _ma_status 1 _ma_message)
    file(REMOVE "${_ma_archive}")
    message(FATAL_ERROR "Could not download miniaudio (${_ma_message}) from ${_ma_url}. "
      "Without a network, download that file elsewhere and pass "
      "-DAMBFPLUS_MINIAUDIO_HEADER=<path to its miniaudio/miniaudio.h> (pip: -C "
      "cmake.define.AMBFPLUS_MINIAUDIO_HEADER=...).")
  endif()
  file(ARCHIVE_EXTRACT INPUT "${_ma_archive}" DESTINATION ${CMAKE_BINARY_DIR}/_downloads
    PATTERNS miniaudio-1.71/miniaudio/miniaudio.h)
  configure_file(${CMAKE_BINARY_DIR}/_downloads/miniaudio-1.71/miniaudio/miniaudio.h
    "${_ma_header}" COPYONLY)
  _ambfplus_check_miniaudio("${_ma_header}" _ma_ok)
  if(NOT _ma_ok)
    message(FATAL_ERROR "${_ma_archive}: its miniaudio/miniaudio.h is not the expected header "
      "(SHA-256 ${_ma_header_sha256})")
  endif()
endif()
