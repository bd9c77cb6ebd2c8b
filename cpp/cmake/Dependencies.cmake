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
