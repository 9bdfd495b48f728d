# The clang + libc++ lane (./course lanes libcxx, tools/cl/lanes.py): the
# toolchain of macOS (clang, LLVM's libc++ and libomp) on Linux, so that what
# Apple's clang rejects or reads differently is seen here. Debian: clang,
# libc++-dev, libc++abi-dev, libomp-dev.
set(CMAKE_CXX_COMPILER clang++)
set(CMAKE_CXX_FLAGS_INIT "-stdlib=libc++")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-stdlib=libc++")
