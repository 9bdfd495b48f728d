# The MinGW lane's Eigen (toolchain.cmake): Debian's headers, staged.
include("${CMAKE_CURRENT_LIST_DIR}/../stage.cmake")
cl_mingw_header_target(Eigen3::Eigen Eigen/Core /eigen3 libeigen3-dev)
