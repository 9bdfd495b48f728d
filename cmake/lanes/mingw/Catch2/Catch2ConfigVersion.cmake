# The version of the header staged: Debian's own version file (plain CMake).
include(/usr/lib/cmake/Catch2/Catch2ConfigVersion.cmake OPTIONAL RESULT_VARIABLE _cl_found)
if(NOT _cl_found)
  set(PACKAGE_VERSION_UNSUITABLE TRUE)
endif()
