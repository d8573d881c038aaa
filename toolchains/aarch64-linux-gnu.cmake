# Cross-compiling sunvo for 64-bit ARM Linux (Raspberry Pi 4/5, Jetson, i.MX8) with Debian's
# crossbuild-essential-arm64. Point SUNVO_SYSROOT (environment or -D) at an arm64 sysroot that
# holds every library sunvo links (Eigen, OpenCV, Ceres, GeographicLib, yaml-cpp, libgpiod);
# scripts/make_arm64_sysroot.sh makes one, by default at build/sysroot-arm64, which is used when
# SUNVO_SYSROOT is empty or unset.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

if(NOT SUNVO_SYSROOT AND DEFINED ENV{SUNVO_SYSROOT})
  set(SUNVO_SYSROOT "$ENV{SUNVO_SYSROOT}")
endif()
if(NOT SUNVO_SYSROOT AND EXISTS "${CMAKE_CURRENT_LIST_DIR}/../build/sysroot-arm64/usr/include")
  get_filename_component(SUNVO_SYSROOT "${CMAKE_CURRENT_LIST_DIR}/../build/sysroot-arm64" ABSOLUTE)
endif()
if(NOT SUNVO_SYSROOT)
  message(FATAL_ERROR "aarch64 toolchain: set SUNVO_SYSROOT (environment or -D) to an arm64 "
                      "sysroot, or run scripts/make_arm64_sysroot.sh")
endif()
# try_compile() projects read this file again; hand them the same sysroot.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES SUNVO_SYSROOT)

set(CMAKE_SYSROOT "${SUNVO_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH "${SUNVO_SYSROOT}")

# Programs (compilers, code generators) come from the host; libraries, headers and CMake package
# files only from the target sysroot.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Tests run under user-mode emulation when cross-compiled; -L makes qemu's loader and library
# look-ups (/lib/ld-linux-aarch64.so.1, /usr/lib/aarch64-linux-gnu/...) resolve in the sysroot.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L "${SUNVO_SYSROOT}")
