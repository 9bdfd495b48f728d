#include "common/source_dir.h"

namespace cl {

// CL_SOURCE_DIR is this file's own definition (CMakeLists.txt; fuzz/CMakeLists.txt).
const char* source_dir() { return CL_SOURCE_DIR; }

}  // namespace cl
