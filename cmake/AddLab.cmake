# add_lab(NAME STUDENT a.cpp [b.cpp ...] [SUPPORT s.cpp ...] [DRIVER d.cpp ...]
#         [DEPENDS earlier_lab ...] [DRIVER_DEPENDS earlier_lab ...] [LIBRARIES target ...])
#
# Files by convention, all under labs/NAME unless said otherwise:
#   STUDENT   the student's .cpp stubs; solutions/NAME holds a reference .cpp of
#             the same name for each (in a student release: only for the labs
#             before the current one, see docs/DESIGN.md §4)
#   SUPPORT   lab code that is not the student's, which the graded tests or a
#             later lab link (the solver code a test or a later lab calls)
#   DRIVER    lab code that only this lab's executables link (its experiments
#             and runs: experiments.cpp, run.cpp), compiled once with main.cpp.
#             A grading build compiles only what the test program and the lab's
#             own executable link, so an earlier lab's DRIVER files are never
#             compiled for a later lab (a file a test or a later lab needs, put
#             here, fails their link with an undefined reference)
#   DEPENDS   the earlier labs this lab's code and graded tests use (and,
#             transitively, theirs: a later lab inherits them)
#   DRIVER_DEPENDS   earlier labs only the executable uses (lab 07's driver
#             compares with lab 04's PBD): not inherited, not in the tests
#   LIBRARIES extra link targets for the lab's code (e.g. OpenMP::OpenMP_CXX)
#   main.cpp  the executable's driver
#   scenes/   the lab's JSON scenes
#   tests/NAME/*.cpp       the graded tests
#   tests/NAME/info/*.cpp  optional: an ungraded measurement the grader prints
#                          (e.g. lab 03's OpenMP speed-up)
#
# A lab HAS A REFERENCE when every one of its STUDENT files is in solutions/NAME.
# Targets:
#   NAME_student                   the student's code (static library)
#   NAME, NAME_tests               the executable and the graded tests, in build/bin.
#                                  Both link this lab's student code and, for each
#                                  earlier lab they use (DEPENDS; the executable
#                                  DRIVER_DEPENDS too), its reference when it has one,
#                                  else the student's code (isolation, docs/DESIGN.md §4);
#                                  NAME then says once on stderr which earlier labs
#                                  run the student's code
#   NAME_info                      the info program, linked like NAME_tests
#   NAME_tests_asan                NAME_tests with the tests and the student's code
#                                  under -fsanitize=address,undefined (not built by
#                                  default; the grader reruns a crashed case in it)
# Only for a lab with a reference:
#   NAME_reference                 the reference code (static library)
#   NAME_solution, NAME_tests_solution, NAME_info_solution   the same, reference throughout
#
# Drivers see CL_LAB_NAME (the lab, for summaries), CL_PROGRAM_NAME (the
# executable, for messages) and CL_LAB_SCENE_DIR (absolute path of scenes/, an
# expression, cl::lab_scene_dir, so that the tree's path is compiled into
# common/scene.cpp alone).
#
# The build writes ${PROJECT_BINARY_DIR}/labs.json, read by tools/course.py: per
# lab its student files, whether it has a reference, its earlier labs and
# whether the graded tests link each one's reference or the student's code
# ("links"), and the same for the executable ("program_links": DRIVER_DEPENDS
# too). `./course grade` prints it per lab (tools/cl/labs.py, link_line).

set_property(GLOBAL PROPERTY CL_LAB_MANIFEST "")
set(CL_SANITIZE_FLAGS -fsanitize=address,undefined -g -O1 -fno-omit-frame-pointer)

function(add_lab name)
  cmake_parse_arguments(LAB "" "" "STUDENT;SUPPORT;DRIVER;DEPENDS;DRIVER_DEPENDS;LIBRARIES" ${ARGN})
  set(lab_dir "${PROJECT_SOURCE_DIR}/labs/${name}")

  set(solution_dir "${PROJECT_SOURCE_DIR}/solutions/${name}")

  # Earlier labs this one needs, transitively, newest first (static link order).
  _cl_closure(closure ${LAB_DEPENDS})
  set_property(GLOBAL PROPERTY CL_LAB_CLOSURE_${name} ${closure})
  # The executable's: those, and what only its driver uses (not inherited).
  _cl_closure(driver_closure ${LAB_DEPENDS} ${LAB_DRIVER_DEPENDS})

  set(closure_support ${name}_support)
  foreach(dep IN LISTS closure)
    list(APPEND closure_support ${dep}_support)
  endforeach()
  set(driver_support ${name}_support)
  foreach(dep IN LISTS driver_closure)
    list(APPEND driver_support ${dep}_support)
  endforeach()

  # A reference exists when all of the student files are in solutions/NAME; some
  # but not all is a broken tree, not a release.
  set(student_sources "")
  set(reference_sources "")
  set(present "")
  set(absent "")
  foreach(file IN LISTS LAB_STUDENT)
    list(APPEND student_sources "${lab_dir}/${file}")
    list(APPEND reference_sources "${solution_dir}/${file}")
    if(EXISTS "${solution_dir}/${file}")
      list(APPEND present ${file})
    else()
      list(APPEND absent ${file})
    endif()
  endforeach()
  if(present AND absent)
    message(FATAL_ERROR "${name}: solutions/${name} has ${present} but not ${absent}")
  endif()
  if(absent)
    set(has_reference OFF)
  else()
    set(has_reference ON)
  endif()
  set_property(GLOBAL PROPERTY CL_LAB_HAS_REFERENCE_${name} ${has_reference})
  # Re-configure when a reference arrives (a past lab's solution, released late).
  if(EXISTS "${PROJECT_SOURCE_DIR}/solutions")
    set_property(DIRECTORY "${PROJECT_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
                 "${PROJECT_SOURCE_DIR}/solutions")
  endif()
  if(EXISTS "${solution_dir}")
    set_property(DIRECTORY "${PROJECT_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${solution_dir}")
  endif()

  if(LAB_SUPPORT)
    list(TRANSFORM LAB_SUPPORT PREPEND "${lab_dir}/")
    add_library(${name}_support STATIC ${LAB_SUPPORT})
    target_link_libraries(${name}_support PUBLIC common ${LAB_LIBRARIES})
    target_include_directories(${name}_support PUBLIC "${lab_dir}")
    # A lab's given files compile as one batch that parses their headers once
    # (lab 05's three: 7.0 s of CPU, not 9.8 s, in the sanitizer build).
    cl_unity(${name}_support 0)
  else()
    add_library(${name}_support INTERFACE)
    target_include_directories(${name}_support INTERFACE "${lab_dir}")
    target_link_libraries(${name}_support INTERFACE common ${LAB_LIBRARIES})
  endif()

  add_library(${name}_student STATIC ${student_sources})
  target_link_libraries(${name}_student PUBLIC ${name}_support)
  if(has_reference)
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

  # Link lines: [support, implementation] for this lab, then for each earlier
  # lab: the tests' (closure) and the executables' (driver_closure).
  _cl_link_chains(${name} "${closure}" reference_chain isolated_chain student_tested)
  _cl_links_json(links_json "${closure}" "${student_tested}")
  _cl_link_chains(${name} "${driver_closure}" driver_reference_chain driver_isolated_chain student_earlier)
  _cl_links_json(program_links_json "${driver_closure}" "${student_earlier}")
  # A lab with a reference can only have earlier labs with references (a
  # release ships the past ones, the full tree all of them).
  foreach(dep IN LISTS driver_closure)
    get_property(dep_has_reference GLOBAL PROPERTY CL_LAB_HAS_REFERENCE_${dep})
    if(has_reference AND NOT dep_has_reference)
      message(FATAL_ERROR "${name} has a reference in solutions/ but ${dep}, which it needs, has none")
    endif()
  endforeach()

  set(bin_dir "${PROJECT_BINARY_DIR}/bin")
  set(scene_definition "CL_LAB_SCENE_DIR=cl::lab_scene_dir(\"${name}\")")

  # main.cpp and the DRIVER files are compiled once, for NAME and NAME_solution
  # alike: what differs (the program's name, the earlier labs it runs as the
  # student's code) is a two-line source generated per executable
  # (cl_program_name, common/cli.h). Only the executables link them, so
  # building a later lab's tests or executable never compiles them.
  set(driver_sources "${lab_dir}/main.cpp")
  foreach(file IN LISTS LAB_DRIVER)
    list(APPEND driver_sources "${lab_dir}/${file}")
  endforeach()
  add_library(${name}_driver OBJECT ${driver_sources})
  # One batch, as the support files: main.cpp and the experiments parse the
  # same headers (Eigen, nlohmann/json, common/), about 3 s of CPU a file.
  cl_unity(${name}_driver 0)
  target_link_libraries(${name}_driver PRIVATE ${driver_support})
  foreach(dep IN LISTS driver_closure)
    target_include_directories(${name}_driver PRIVATE "${PROJECT_SOURCE_DIR}/labs/${dep}")
  endforeach()
  target_compile_definitions(${name}_driver PRIVATE ${scene_definition} CL_LAB_NAME="${name}"
                             CL_PROGRAM_NAME=cl_program_name CL_STUDENT_EARLIER_LABS=cl_student_earlier_labs)
  list(SORT student_earlier)
  list(JOIN student_earlier " " student_earlier)
  _cl_identity_source(${name} "${student_earlier}" identity)
  add_executable(${name} "${identity}")
  target_link_libraries(${name} PRIVATE ${name}_driver ${driver_isolated_chain} common)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

  # The graded tests are compiled once and linked twice: against the student's
  # chain (NAME_tests) and the reference's (NAME_tests_solution).
  file(GLOB test_sources CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tests/${name}/*.cpp")
  add_library(${name}_test_objects OBJECT ${test_sources})
  target_link_libraries(${name}_test_objects PRIVATE cl_catch2 ${closure_support})
  target_compile_definitions(${name}_test_objects PRIVATE ${scene_definition})
  cl_unity_tests(${name}_test_objects)
  cl_test_optimisation(${name}_test_objects)
  add_executable(${name}_tests $<TARGET_OBJECTS:${name}_test_objects>)
  target_link_libraries(${name}_tests PRIVATE catch_main ${isolated_chain} common)
  set_target_properties(${name}_tests PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

  # The grader's crash rerun (not built by default): the graded tests and this
  # lab's student code compiled with AddressSanitizer and UBSan; everything
  # else links as in NAME_tests, uninstrumented, so only a few files compile.
  add_executable(${name}_tests_asan EXCLUDE_FROM_ALL ${test_sources} ${student_sources})
  # The tests in batches as in NAME_tests; the student's files as written.
  set_source_files_properties(${student_sources} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
  cl_unity_tests(${name}_tests_asan)
  target_link_libraries(${name}_tests_asan PRIVATE catch_main ${name}_support)
  list(LENGTH isolated_chain chain_length)
  if(chain_length GREATER 2)
    list(SUBLIST isolated_chain 2 -1 earlier_chain)
    target_link_libraries(${name}_tests_asan PRIVATE ${earlier_chain})
  endif()
  target_link_libraries(${name}_tests_asan PRIVATE common)
  target_compile_definitions(${name}_tests_asan PRIVATE ${scene_definition})
  target_compile_options(${name}_tests_asan PRIVATE ${CL_SANITIZE_FLAGS})
  target_link_options(${name}_tests_asan PRIVATE -fsanitize=address,undefined)
  set_target_properties(${name}_tests_asan PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

  file(GLOB info_sources CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tests/${name}/info/*.cpp")
  if(info_sources)
    add_library(${name}_info_objects OBJECT ${info_sources})
    target_link_libraries(${name}_info_objects PRIVATE ${closure_support})
    target_compile_definitions(${name}_info_objects PRIVATE ${scene_definition})
    cl_test_optimisation(${name}_info_objects)
    add_executable(${name}_info $<TARGET_OBJECTS:${name}_info_objects>)
    target_link_libraries(${name}_info PRIVATE ${isolated_chain} common)
    set_target_properties(${name}_info PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")
  endif()

  if(has_reference)
    _cl_identity_source(${name}_solution "" identity)
    add_executable(${name}_solution "${identity}")
    target_link_libraries(${name}_solution PRIVATE ${name}_driver ${driver_reference_chain} common)
    set_target_properties(${name}_solution PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

    add_executable(${name}_tests_solution $<TARGET_OBJECTS:${name}_test_objects>)
    target_link_libraries(${name}_tests_solution PRIVATE catch_main ${reference_chain} common)
    set_target_properties(${name}_tests_solution PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")

    # Ungraded tests of the lab's given code ([labNN_given], on the reference):
    # part of the unit tests (ctest -L unit), never of a score. Registered only
    # for a lab that has such cases: a filter that matches nothing passes.
    string(SUBSTRING "${name}" 0 5 lab_tag)
    set(given_cases "")
    foreach(file IN LISTS test_sources)
      file(STRINGS "${file}" found REGEX "\\[${lab_tag}_given\\]")
      list(APPEND given_cases ${found})
    endforeach()
    if(given_cases)
      add_test(NAME ${name}_given COMMAND ${name}_tests_solution "[${lab_tag}_given]")
      set_tests_properties(${name}_given PROPERTIES LABELS unit)
    endif()

    if(info_sources)
      add_executable(${name}_info_solution $<TARGET_OBJECTS:${name}_info_objects>)
      target_link_libraries(${name}_info_solution PRIVATE ${reference_chain} common)
      set_target_properties(${name}_info_solution PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${bin_dir}")
    endif()
  endif()

  # This lab's entry in labs.json.
  set(student_json "")
  foreach(file IN LISTS LAB_STUDENT)
    list(APPEND student_json "\"labs/${name}/${file}\"")
  endforeach()
  set(deps_json "")
  foreach(dep IN LISTS closure)
    list(APPEND deps_json "\"${dep}\"")
  endforeach()
  if(has_reference)
    set(reference_json true)
  else()
    set(reference_json false)
  endif()
  if(info_sources)
    set(info_json true)
  else()
    set(info_json false)
  endif()
  list(JOIN student_json ", " student_json)
  list(JOIN deps_json ", " deps_json)
  list(JOIN links_json ", " links_json)
  list(JOIN program_links_json ", " program_links_json)
  set_property(GLOBAL APPEND PROPERTY CL_LAB_MANIFEST
    "    \"${name}\": {\"student\": [${student_json}], \"reference\": ${reference_json}, \"info\": ${info_json},\n      \"deps\": [${deps_json}], \"links\": {${links_json}}, \"program_links\": {${program_links_json}}}")
endfunction()

# Writes the two-line source that names executable `program` (cl_program_name,
# cl_student_earlier_labs in common/cli.h); sets `out` to its path.
# The labs given after `out` and, transitively, the labs they need, newest
# first (static link order), each once.
function(_cl_closure out)
  set(result "")
  foreach(dep IN LISTS ARGN)
    get_property(dep_closure GLOBAL PROPERTY CL_LAB_CLOSURE_${dep})
    list(APPEND result ${dep} ${dep_closure})
  endforeach()
  list(REMOVE_DUPLICATES result)
  list(SORT result ORDER DESCENDING)
  set(${out} ${result} PARENT_SCOPE)
endfunction()

# The link lines of a lab's programs over `deps` (earlier labs, latest first):
# [support, implementation] for the lab, then for each dep. The reference
# chain links every reference; the isolated one the lab's student code and each
# earlier lab's reference where it has one, else its student code (those labs
# are listed in `student_out`).
function(_cl_link_chains name deps reference_out isolated_out student_out)
  set(reference ${name}_support ${name}_reference)
  set(isolated ${name}_support ${name}_student)
  set(student "")
  foreach(dep IN LISTS deps)
    get_property(dep_has_reference GLOBAL PROPERTY CL_LAB_HAS_REFERENCE_${dep})
    list(APPEND reference ${dep}_support ${dep}_reference)
    if(dep_has_reference)
      list(APPEND isolated ${dep}_support ${dep}_reference)
    else()
      list(APPEND isolated ${dep}_support ${dep}_student)
      list(APPEND student ${dep})
    endif()
  endforeach()
  set(${reference_out} ${reference} PARENT_SCOPE)
  set(${isolated_out} ${isolated} PARENT_SCOPE)
  set(${student_out} ${student} PARENT_SCOPE)
endfunction()

function(_cl_identity_source program student_earlier out)
  set(path "${PROJECT_BINARY_DIR}/identity/${program}.cpp")
  string(CONFIGURE [=[// Generated by cmake/AddLab.cmake: who this executable is.
extern "C" const char cl_program_name[] = "@program@";
extern "C" const char cl_student_earlier_labs[] = "@student_earlier@";
]=] text @ONLY)
  file(CONFIGURE OUTPUT "${path}" CONTENT "${text}" @ONLY)
  set(${out} "${path}" PARENT_SCOPE)
endfunction()

# Sets `out` to labs.json's list of `deps`, each "student" when it is in
# `student` (the earlier labs linked as the student's code), else "reference".
function(_cl_links_json out deps student)
  set(entries "")
  foreach(dep IN LISTS deps)
    if(dep IN_LIST student)
      list(APPEND entries "\"${dep}\": \"student\"")
    else()
      list(APPEND entries "\"${dep}\": \"reference\"")
    endif()
  endforeach()
  set(${out} "${entries}" PARENT_SCOPE)
endfunction()

# Called once the whole CMakeLists.txt is read (cmake_language DEFER): labs.json,
# with what the build has that grading depends on ("build": OpenMP, and the
# Catch2 version's major number).
function(_cl_write_lab_manifest)
  get_property(entries GLOBAL PROPERTY CL_LAB_MANIFEST)
  list(JOIN entries ",\n" body)
  if(CL_HAVE_OPENMP)
    set(openmp true)
  else()
    set(openmp false)
  endif()
  file(CONFIGURE OUTPUT "${PROJECT_BINARY_DIR}/labs.json"
       CONTENT "{\n  \"build\": {\"openmp\": ${openmp}, \"catch2\": ${CL_CATCH2_MAJOR}},\n  \"labs\": {\n${body}\n  }\n}\n" @ONLY)
endfunction()
cmake_language(DEFER CALL _cl_write_lab_manifest)
