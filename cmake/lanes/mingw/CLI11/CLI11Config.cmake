# The MinGW lane's CLI11 (toolchain.cmake): Debian's headers, staged.
include("${CMAKE_CURRENT_LIST_DIR}/../stage.cmake")
cl_mingw_header_target(CLI11::CLI11 CLI/CLI.hpp "" libcli11-dev)
