# The MinGW-w64 lane (./course lanes mingw, tools/cl/lanes.py): a native
# Windows build, cross-compiled on Debian with g++-mingw-w64-x86-64 (the posix
# thread model: std::thread), linked statically so that Wine, or Windows, runs
# a program without any DLL beside it.
#
# The libraries the course uses are header-only (Eigen, nlohmann/json, CLI11,
# Catch2 2.13, Boost's Beast and Asio). Debian's packages install them under /usr/include, which must
# never be on a MinGW include path (glibc's headers live there too), so the
# package configs beside this file stage them (stage.cmake: a folder of links
# in the build tree) and point their targets there. On Windows itself, MSYS2's
# packages (mingw-w64-x86_64-eigen3, -nlohmann-json, -cli11, -catch) ship the
# real configs, and none of this is needed.
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CMAKE_CXX_COMPILER x86_64-w64-mingw32-g++-posix)
set(CMAKE_RC_COMPILER x86_64-w64-mingw32-windres)

# Libraries and headers only from the MinGW tree; packages only from here.
set(CMAKE_FIND_ROOT_PATH /usr/x86_64-w64-mingw32 "${CMAKE_CURRENT_LIST_DIR}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
foreach(package Eigen3 nlohmann_json CLI11 Catch2 Boost)
  set(${package}_DIR "${CMAKE_CURRENT_LIST_DIR}/${package}")
endforeach()

# libstdc++, libgcc and winpthread linked in (no DLLs). Static libgomp cannot
# be linked with the test programs of labs 03 and 12, which define its entry
# points to count regions (tests/support/openmp_regions.h finds the real ones
# in libgomp-1.dll), so the lane configures without OpenMP (lanes.py).
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_DISABLE_FIND_PACKAGE_OpenMP ON CACHE BOOL "")
# The configs here are Catch2 2.13's: never look for 3.x.
set(CL_CATCH2_2 ON CACHE BOOL "")
# The live mode's server (Boost.Beast over Asio, common/live_server.cpp) is
# compiled too: Boost's headers are staged like the others (Boost/).
