# add_lab(NAME STUDENT a.cpp [b.cpp ...] [SUPPORT s.cpp ...] [DEPENDS earlier_lab ...]
#         [LIBRARIES target ...])
#
# Files by convention, all under labs/NAME unless said otherwise:
#   STUDENT   the student's .cpp stubs; solutions/NAME holds a reference .cpp of
#             the same name for each
#   SUPPORT   lab code that is not the student's (used by the driver and tests)
#   LIBRARIES extra link targets for the lab's code (e.g. OpenMP::OpenMP_CXX)
#   main.cpp  the executable's driver
#   scenes/   the lab's JSON scenes
#   tests/NAME/*.cpp  the graded tests
#
# Targets:
#   NAME_student, NAME_reference   the two implementations (static libraries)
#   NAME, NAME_solution            the executables, in build/bin
#   NAME_tests                     graded tests: this lab's student code, earlier
#                                  labs' reference code (isolation, COURSE.md §4)
#   NAME_tests_solution            graded tests against reference code throughout
# Drivers see CL_LAB_NAME (the lab, for summaries), CL_PROGRAM_NAME (the
# executable, for messages) and CL_LAB_SCENE_DIR (absolute path of scenes/).
function(add_lab name)
  cmake_parse_arguments(LAB "" "" "STUDENT;SUPPORT;DEPENDS;LIBRARIES" ${ARGN})
  set(lab_dir "${PROJECT_SOURCE_DIR}/labs/${name}")
  set(solution_dir "${PROJECT_SOURCE_DIR}/solutions/${name}")

  # Earlier labs this one needs, transitively, newest first (static link order).
  set(closure "")
  foreach(dep IN LISTS LAB_DEPENDS)
    get_property(dep_closure GLOBAL PROPERTY CL_LAB_CLOSURE_${dep})
    list(APPEND closure ${dep} ${dep_closure})
  endforeach()
  list(REMOVE_DUPLICATES closure)
  list(SORT closure ORDER DESCENDING)
  set_property(GLOBAL PROPERTY CL_LAB_CLOSURE_${name} ${closure})

  set(student_sources "")
  set(reference_sources "")
  foreach(file IN LISTS LAB_STUDENT)
    list(APPEND student_sources "${lab_dir}/${file}")
    list(APPEND reference_sources "${solution_dir}/${file}")
    if(CL_HAVE_SOLUTIONS AND NOT EXISTS "${solution_dir}/${file}")
      message(FATAL_ERROR "${name}: solutions/${name}/${file} is missing")
    endif()
  endforeach()

  if(LAB_SUPPORT)
    list(TRANSFORM LAB_SUPPORT PREPEND "${lab_dir}/")
    add_library(${name}_support STATIC ${LAB_SUPPORT})
    target_link_libraries(${name}_support PUBLIC common ${LAB_LIBRARIES})
    target_include_directories(${name}_support PUBLIC "${lab_dir}")
  else()
    add_library(${name}_support INTERFACE)
    target_include_directories(${name}_support INTERFACE "${lab_dir}")
    target_link_libraries(${name}_support INTERFACE common ${LAB_LIBRARIES})
  endif()

  add_library(${name}_student STATIC ${student_sources})
  target_link_libraries(${name}_student PUBLIC ${name}_support)
  if(CL_HAVE_SOLUTIONS)
    add_library(${name}_reference STATIC ${reference_sources})
    target_link_libraries(${name}_reference PUBLIC ${name}_support)
    # The reference includes the header beside the stub: one contract, no drift.
    target_include_directories(${name}_reference PRIVATE "${lab_dir}")
  endif()
  if(LAB_SUPPORT)
    set(scope PUBLIC)
  else()
    set(scope INTERFACE)
  endif()
  foreach(dep IN LISTS closure)
    target_include_directories(${name}_support ${scope} "${PROJECT_SOURCE_DIR}/labs/${dep}")
  endforeach()

  # Link lines: [support, implementation] for this lab, then for each earlier lab.
  set(student_chain ${name}_support ${name}_student)
  set(reference_chain ${name}_support ${name}_reference)
  set(isolated_chain ${name}_support ${name}_student)
  foreach(dep IN LISTS closure)
    list(APPEND student_chain ${dep}_support ${dep}_student)
    list(APPEND reference_chain ${dep}_support ${dep}_reference)
    if(CL_HAVE_SOLUTIONS)
      list(APPEND isolated_chain ${dep}_support ${dep}_reference)
    else()
      list(APPEND isolated_chain ${dep}_support ${dep}_student)
    endif()
  endforeach()

  set(bin_dir "${PROJECT_BINARY_DIR}/bin")
  set(scene_definition CL_LAB_SCENE_DIR="${lab_dir}/scenes")

  add_executable(${name} "${lab_dir}/main.cpp")
  target_link_libraries(${name} PRIVATE ${student_chain} common)
  target_compile_definitions(${name} PRIVATE ${scene_definition} CL_LAB_NAME="${name}" CL_PROGRAM_NAME="${name}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

  file(GLOB test_sources CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tests/${name}/*.cpp")
  add_executable(${name}_tests ${test_sources})
  target_link_libraries(${name}_tests PRIVATE catch_main ${isolated_chain} common)
  target_compile_definitions(${name}_tests PRIVATE ${scene_definition})
  set_target_properties(${name}_tests PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

  if(CL_HAVE_SOLUTIONS)
    add_executable(${name}_solution "${lab_dir}/main.cpp")
    target_link_libraries(${name}_solution PRIVATE ${reference_chain} common)
    target_compile_definitions(${name}_solution PRIVATE ${scene_definition} CL_LAB_NAME="${name}" CL_PROGRAM_NAME="${name}_solution")
    set_target_properties(${name}_solution PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

    add_executable(${name}_tests_solution ${test_sources})
    target_link_libraries(${name}_tests_solution PRIVATE catch_main ${reference_chain} common)
    target_compile_definitions(${name}_tests_solution PRIVATE ${scene_definition})
    set_target_properties(${name}_tests_solution PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")
  endif()
endfunction()
