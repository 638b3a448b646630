# Finds every dependency; a missing one stops configure with the Debian package that provides it.
# scripts/install-deps.sh installs them all.

function(hapticd_missing what package)
  message(FATAL_ERROR
    "hapticd: ${what} not found. Install the Debian package '${package}' "
    "(scripts/install-deps.sh installs every dependency).")
endfunction()

# A pkg-config module as the imported target PkgConfig::<prefix> (a macro: <prefix>_FOUND and the
# other variables pkg_check_modules sets stay in the caller's scope).
macro(hapticd_require_module prefix module what package)
  pkg_check_modules(${prefix} QUIET IMPORTED_TARGET ${module})
  if(NOT ${prefix}_FOUND)
    hapticd_missing("${what}" "${package}")
  endif()
endmacro()

find_package(PkgConfig QUIET)
if(NOT PkgConfig_FOUND)
  hapticd_missing("pkg-config" "pkg-config")
endif()

# GLM ships no CMake config on Debian 12; it is header-only.
find_path(GLM_INCLUDE_DIR glm/glm.hpp)
if(NOT GLM_INCLUDE_DIR)
  hapticd_missing("GLM (glm/glm.hpp)" "libglm-dev")
endif()
add_library(hapticd_glm INTERFACE)
target_include_directories(hapticd_glm SYSTEM INTERFACE ${GLM_INCLUDE_DIR})
target_compile_definitions(hapticd_glm INTERFACE GLM_FORCE_XYZW_ONLY GLM_ENABLE_EXPERIMENTAL)

find_package(Qhull QUIET)
if(NOT TARGET Qhull::qhull_r)
  hapticd_missing("Qhull (reentrant library qhull_r)" "libqhull-dev")
endif()

find_package(nlohmann_json 3 QUIET)
if(NOT nlohmann_json_FOUND)
  hapticd_missing("nlohmann_json" "nlohmann-json3-dev")
endif()

find_package(CLI11 QUIET)
if(NOT CLI11_FOUND)
  hapticd_missing("CLI11" "libcli11-dev")
endif()

# Debian's tinygltf is a shared library with the implementation compiled in: include tiny_gltf.h,
# never define TINYGLTF_IMPLEMENTATION.
find_package(TinyGLTF QUIET)
if(NOT TARGET TinyGLTF::TinyGLTF)
  hapticd_missing("tinygltf" "libtinygltf-dev")
endif()

# compressed glTF geometry (core/scene/compression.cpp): KHR_draco_mesh_compression and
# EXT_meshopt_compression
find_package(draco QUIET)
if(NOT TARGET draco::draco)
  hapticd_missing("Draco (draco::draco)" "libdraco-dev")
endif()
find_package(meshoptimizer QUIET)
if(NOT TARGET meshoptimizer::meshoptimizer)
  hapticd_missing("meshoptimizer" "libmeshoptimizer-dev")
endif()

find_package(tomlplusplus 3 QUIET)
if(NOT TARGET tomlplusplus::tomlplusplus)
  hapticd_missing("toml++" "libtomlplusplus-dev")
endif()

hapticd_require_module(SYSTEMD libsystemd "libsystemd" "libsystemd-dev")
hapticd_require_module(HIDAPI hidapi-hidraw "hidapi (hidraw)" "libhidapi-dev")
hapticd_require_module(LIBUSB libusb-1.0 "libusb-1.0" "libusb-1.0-0-dev")
hapticd_require_module(SODIUM libsodium "libsodium" "libsodium-dev")
find_package(Threads REQUIRED)

if(HAPTICD_BUILD_TESTS)
  find_package(GTest QUIET)
  if(NOT GTest_FOUND)
    hapticd_missing("GoogleTest" "libgtest-dev")
  endif()
endif()

if(HAPTICD_BUILD_BENCH)
  find_package(benchmark QUIET)
  if(NOT benchmark_FOUND)
    hapticd_missing("Google Benchmark" "libbenchmark-dev")
  endif()
  hapticd_require_module(CCD ccd "libccd" "libccd-dev")
  hapticd_require_module(FCL fcl "FCL" "libfcl-dev")
  hapticd_require_module(BULLET bullet-float64 "Bullet (double precision build)" "libbullet-dev")
endif()
