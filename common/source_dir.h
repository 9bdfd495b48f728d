#pragma once

namespace cl {

// The course tree's absolute path (the folder that holds labs/ and tools/),
// without a trailing slash. It is compiled into one small file,
// common/source_dir.cpp, the only compile line that names the tree: the rest
// of common/ then compiles in unity batches (CMakeLists.txt) with the same
// command in every tree, so ccache's base dir reuses them across trees.
const char* source_dir();

}  // namespace cl
