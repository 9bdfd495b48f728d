# The version of the headers staged: Debian's own version file (plain CMake).
include(/usr/share/cmake/CLI11/CLI11ConfigVersion.cmake OPTIONAL RESULT_VARIABLE _cl_found)
if(NOT _cl_found)
  set(PACKAGE_VERSION_UNSUITABLE TRUE)
endif()
