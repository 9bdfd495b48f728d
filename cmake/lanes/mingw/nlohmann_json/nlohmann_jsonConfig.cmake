# The MinGW lane's nlohmann/json (toolchain.cmake): Debian's headers, staged.
include("${CMAKE_CURRENT_LIST_DIR}/../stage.cmake")
cl_mingw_header_target(nlohmann_json::nlohmann_json nlohmann/json.hpp "" nlohmann-json3-dev)
