# The MinGW lane's Catch2 2.13 (toolchain.cmake): Debian's single header,
# staged, and its CMake module (Catch.cmake: catch_discover_tests, plain CMake).
include("${CMAKE_CURRENT_LIST_DIR}/../stage.cmake")
cl_mingw_header_target(Catch2::Catch2 catch2/catch.hpp "" catch2)
list(APPEND CMAKE_MODULE_PATH /usr/lib/cmake/Catch2)
