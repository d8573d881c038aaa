# Cross-compiling sunvo for 64-bit ARM Linux (Raspberry Pi 4/5, Jetson, i.MX8) with Debian's
# crossbuild-essential-arm64. Point SUNVO_SYSROOT (environment or -D) at an arm64 sysroot that
# holds every library sunvo links (Eigen, OpenCV, Ceres, GeographicLib, yaml-cpp, libgpiod).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

if(NOT SUNVO_SYSROOT AND DEFINED ENV{SUNVO_SYSROOT})
  set(SUNVO_SYSROOT "$ENV{SUNVO_SYSROOT}")
endif()
if(SUNVO_SYSROOT)
  set(CMAKE_SYSROOT "${SUNVO_SYSROOT}")
  set(CMAKE_FIND_ROOT_PATH "${SUNVO_SYSROOT}")
endif()

# Programs (compilers, code generators) come from the host; libraries, headers and CMake package
# files only from the target sysroot.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Tests run under user-mode emulation when cross-compiled.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L "${SUNVO_SYSROOT}")
