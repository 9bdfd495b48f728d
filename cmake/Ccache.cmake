# Included by the course's CMakeLists.txt and by fuzz/CMakeLists.txt (a project
# of its own, built with clang++), so that both builds use ccache alike.
#
# ccache when it is installed (never required): a rebuild after `git checkout`,
# a second build tree of the same checkout, or CI's next run reuse the compiles
# that did not change. Its sloppiness lets it cache a file whose includes are
# only seconds old (the unity batches CMake has just written).
# Its depend mode reads the include list from the compiler's -MD file instead
# of running the preprocessor first on a miss: lab 05's tests from a clean tree
# and an empty cache took 150-176 s of CPU through ccache, 149-150 s in depend
# mode, 135-138 s without ccache (two rounds each); a rebuild hits alike.
# (No CCACHE_BASEDIR here: it would hand the compiler relative paths, and the
# grader's messages, compiler errors and sanitizer frames would read "../labs/".
# Only ./course test sets it, for its own builds: tools/cl/checks.py.)
find_program(CL_CCACHE ccache)
if(CL_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER AND NOT DEFINED ENV{CMAKE_CXX_COMPILER_LAUNCHER})
  set(CMAKE_CXX_COMPILER_LAUNCHER "${CMAKE_COMMAND}" -E env CCACHE_DEPEND=1
      "CCACHE_SLOPPINESS=time_macros,include_file_mtime,include_file_ctime" "${CL_CCACHE}")
endif()
