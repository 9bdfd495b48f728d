# Included by the package configs of the MinGW lane (toolchain.cmake): links
# to Debian's header-only libraries in one folder of the build tree,
# CL_MINGW_INCLUDE, which the imported targets name as their include
# directory, so that no MinGW compile line ever names /usr/include.
set(CL_MINGW_INCLUDE "${CMAKE_BINARY_DIR}/mingw-include")
foreach(entry nlohmann CLI catch2 boost eigen3)
  if(NOT EXISTS "${CL_MINGW_INCLUDE}/${entry}" AND EXISTS "/usr/include/${entry}")
    file(MAKE_DIRECTORY "${CL_MINGW_INCLUDE}")
    file(CREATE_LINK "/usr/include/${entry}" "${CL_MINGW_INCLUDE}/${entry}" SYMBOLIC)
  endif()
endforeach()

# cl_mingw_header_target(TARGET HEADER [SUBDIR]): the INTERFACE target TARGET
# whose include directory is CL_MINGW_INCLUDE[/SUBDIR], which must hold HEADER
# (else the package is not found, with the Debian package to install).
macro(cl_mingw_header_target target header subdir package)
  set(_cl_dir "${CL_MINGW_INCLUDE}${subdir}")
  if(NOT EXISTS "${_cl_dir}/${header}")
    set(${CMAKE_FIND_PACKAGE_NAME}_FOUND FALSE)
    set(${CMAKE_FIND_PACKAGE_NAME}_NOT_FOUND_MESSAGE "/usr/include${subdir}/${header} not found (apt-get install ${package})")
    return()
  endif()
  if(NOT TARGET ${target})
    add_library(${target} INTERFACE IMPORTED)
    set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_cl_dir}")
  endif()
endmacro()
