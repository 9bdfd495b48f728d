# The MinGW lane's Boost (toolchain.cmake): Debian's headers, staged. The live
# mode's server uses Boost.Beast and Asio, header-only, as Boost::headers.
include("${CMAKE_CURRENT_LIST_DIR}/../stage.cmake")
cl_mingw_header_target(Boost::headers boost/version.hpp "" libboost-dev)
