# FlotsamTesting: registration of Fortran test suites with CTest (docs/testing.md).
#
#   flotsam_add_test_suite(NAME <suite> SOURCES <files...> TESTS <procedures...>
#                          [MPI] [RANKS <n>...] [LABELS <label>...] [TIMEOUT <seconds>]
#                          [LINK_LIBRARIES <targets>...])
#
# <suite> is the name of the Fortran module that holds the test procedures (module procedures,
# `subroutine t()` for serial suites, `subroutine t(comm)` with `type(MPI_Comm), intent(in)` for MPI
# suites). A driver program is generated from tests/framework/{serial,mpi}_driver.f90.in; it runs
# the TESTS in the order given. One CTest test is added per rank count:
#   serial suite: <suite>
#   MPI suite:    <suite>_np<N> for each N in RANKS (default 1 2 4), run through MPIEXEC_EXECUTABLE.
# Every test runs in its own working directory <build>/.../run/<test name>, labelled LABELS (default
# `unit`) plus `serial` or `mpi`.
#
# With -DFLOTSAM_USE_PFUNIT=ON and an installed pFUnit, each suite is also wrapped in a generated .pf
# file and registered with pFUnit's add_pfunit_ctest as <suite>_pfunit.

include_guard(GLOBAL)

set(FLOTSAM_TEST_TIMEOUT 300 CACHE STRING "Default CTest timeout (s) of a Flotsam test suite")
option(FLOTSAM_USE_PFUNIT "Also register every test suite with pFUnit, when pFUnit is installed" OFF)

get_filename_component(_flotsam_framework_dir "${CMAKE_CURRENT_LIST_DIR}/../tests/framework" ABSOLUTE)
set_property(GLOBAL PROPERTY FLOTSAM_TESTING_FRAMEWORK_DIR "${_flotsam_framework_dir}")

set_property(GLOBAL PROPERTY FLOTSAM_HAVE_PFUNIT FALSE)
if(FLOTSAM_USE_PFUNIT)
  find_package(PFUNIT QUIET)
  if(PFUNIT_FOUND)
    set_property(GLOBAL PROPERTY FLOTSAM_HAVE_PFUNIT TRUE)
    message(STATUS "pFUnit ${PFUNIT_VERSION} found: test suites are also registered as <suite>_pfunit")
  else()
    message(STATUS "FLOTSAM_USE_PFUNIT is ON but pFUnit was not found (set PFUNIT_DIR); "
                   "using the built-in test framework only")
  endif()
endif()

# The properties every test of a folder gets, whoever added it. Called by flotsam_add_test_suite, and at the
# end of the folders that add tests of their own (a test's properties can only be set in its folder).
#  - A Debug build (-fcheck=all) prints FLOTSAM_ARRAY_COPY_MESSAGE for each array gfortran copies to pass it
#    to a procedure (docs/conventions.md: gfortran 12 copies at every call, also in a Release build): the
#    test fails on it, its exit code apart.
#  - Open MPI 4 keeps the session directories of all of a user's jobs in one $TMPDIR/ompi.<host>.<uid>; a
#    job that ends removes it when it is empty and can pull it away from a job that is just starting there
#    ("orte_session_dir failed", open-mpi/ompi#8510). `ctest -j` starts such jobs side by side, so the test
#    gets a TMPDIR of its own, <build>/tmp/<test name>.
set(FLOTSAM_ARRAY_COPY_MESSAGE "An array temporary was created")
function(flotsam_finish_folder_tests)
  get_property(folder_tests DIRECTORY PROPERTY TESTS)
  foreach(test IN LISTS folder_tests)
    get_test_property(${test} FAIL_REGULAR_EXPRESSION patterns)
    if(NOT patterns)
      set(patterns "")
    endif()
    if(NOT FLOTSAM_ARRAY_COPY_MESSAGE IN_LIST patterns)
      list(APPEND patterns "${FLOTSAM_ARRAY_COPY_MESSAGE}")
      set_tests_properties(${test} PROPERTIES FAIL_REGULAR_EXPRESSION "${patterns}")
    endif()
    get_test_property(${test} ENVIRONMENT environment)
    if(NOT environment MATCHES "(^|;)TMPDIR=")
      set(tmpdir "${CMAKE_BINARY_DIR}/tmp/${test}")
      file(MAKE_DIRECTORY "${tmpdir}")
      set_property(TEST ${test} APPEND PROPERTY ENVIRONMENT "TMPDIR=${tmpdir}")
    endif()
  endforeach()
endfunction()

# Fortran names: a letter, then letters, digits, underscores; 63 characters at most (F2018).
# 60 for test procedures, to leave room for the pf_ prefix of the pFUnit wrappers.
function(_flotsam_check_fortran_name what name max_length)
  string(LENGTH "${name}" _length)
  if(NOT name MATCHES "^[A-Za-z][A-Za-z0-9_]*$" OR _length GREATER max_length)
    message(FATAL_ERROR "flotsam_add_test_suite: ${what} '${name}' is not a Fortran name of at most "
                        "${max_length} characters")
  endif()
endfunction()

function(flotsam_add_test_suite)
  cmake_parse_arguments(PARSE_ARGV 0 ARG "MPI" "NAME;TIMEOUT" "SOURCES;TESTS;RANKS;LABELS;LINK_LIBRARIES")

  # --- arguments --------------------------------------------------------------------------------
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "flotsam_add_test_suite: unknown arguments: ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(ARG_KEYWORDS_MISSING_VALUES)
    message(FATAL_ERROR "flotsam_add_test_suite(${ARG_NAME}): no value for ${ARG_KEYWORDS_MISSING_VALUES}")
  endif()
  if(NOT ARG_NAME)
    message(FATAL_ERROR "flotsam_add_test_suite: NAME <suite> is required")
  endif()
  set(suite "${ARG_NAME}")
  _flotsam_check_fortran_name("suite (module) name" "${suite}" 60)
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "flotsam_add_test_suite(${suite}): SOURCES is required")
  endif()
  if(NOT ARG_TESTS)
    message(FATAL_ERROR "flotsam_add_test_suite(${suite}): TESTS is required (the procedures to run)")
  endif()
  set(tests ${ARG_TESTS})
  list(REMOVE_DUPLICATES tests)
  if(NOT tests STREQUAL ARG_TESTS)
    message(FATAL_ERROR "flotsam_add_test_suite(${suite}): a test is listed twice in TESTS")
  endif()
  foreach(test IN LISTS tests)
    _flotsam_check_fortran_name("test procedure" "${test}" 60)
  endforeach()

  if(ARG_MPI)
    if(NOT ARG_RANKS)
      set(ARG_RANKS 1 2 4)
    endif()
    list(REMOVE_DUPLICATES ARG_RANKS)
    foreach(np IN LISTS ARG_RANKS)
      if(NOT np MATCHES "^[1-9][0-9]*$")
        message(FATAL_ERROR "flotsam_add_test_suite(${suite}): RANKS must be positive integers, got '${np}'")
      endif()
    endforeach()
    if(NOT MPIEXEC_EXECUTABLE)
      message(FATAL_ERROR "flotsam_add_test_suite(${suite}): MPI suite but no MPIEXEC_EXECUTABLE was found")
    endif()
  elseif(DEFINED ARG_RANKS)
    message(FATAL_ERROR "flotsam_add_test_suite(${suite}): RANKS needs MPI")
  endif()
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT ${FLOTSAM_TEST_TIMEOUT})
  endif()

  # --- the suite's module, compiled once (the pFUnit wrapper links the same objects) ------------
  # Each suite has its own module directory: helper modules of different suites cannot collide.
  set(module_dir "${CMAKE_CURRENT_BINARY_DIR}/${suite}_modules")
  add_library(${suite}_objects OBJECT ${ARG_SOURCES})
  set_target_properties(${suite}_objects PROPERTIES Fortran_MODULE_DIRECTORY "${module_dir}")
  target_include_directories(${suite}_objects PUBLIC "${module_dir}")
  target_link_libraries(${suite}_objects PUBLIC flotsam_testing flotsam_core ${ARG_LINK_LIBRARIES})
  # Ninja's Fortran scan sees a suite's direct module uses only; a derived type changed deeper in the
  # core (a component of a type inside solver_t) leaves the suite's objects with the old layout, and the
  # test then crashes in init. Rebuilding the suite's objects whenever the core library changes costs a
  # few seconds and never runs a stale test.
  set_source_files_properties(${ARG_SOURCES} TARGET_DIRECTORY ${suite}_objects
                              PROPERTIES OBJECT_DEPENDS "${FLOTSAM_CORE_LIBRARY_FILE}")

  # --- the generated driver ---------------------------------------------------------------------
  list(JOIN tests ", &\n      " FLOTSAM_SUITE_ONLY_LIST)
  set(FLOTSAM_SUITE "${suite}")
  set(FLOTSAM_SUITE_CALLS "")
  foreach(test IN LISTS tests)
    if(ARG_MPI)
      string(APPEND FLOTSAM_SUITE_CALLS "   call run_mpi_test('${test}', &\n                     ${test}, MPI_COMM_WORLD)\n")
    else()
      string(APPEND FLOTSAM_SUITE_CALLS "   call run_test('${test}', &\n                 ${test})\n")
    endif()
  endforeach()
  get_property(framework_dir GLOBAL PROPERTY FLOTSAM_TESTING_FRAMEWORK_DIR)
  if(ARG_MPI)
    set(template "${framework_dir}/mpi_driver.f90.in")
  else()
    set(template "${framework_dir}/serial_driver.f90.in")
  endif()
  set(driver "${CMAKE_CURRENT_BINARY_DIR}/${suite}_driver.f90")
  configure_file("${template}" "${driver}" @ONLY)

  add_executable(${suite} "${driver}")
  set_target_properties(${suite} PROPERTIES Fortran_MODULE_DIRECTORY "${module_dir}")
  target_link_libraries(${suite} PRIVATE ${suite}_objects)

  # --- one CTest test per rank count ------------------------------------------------------------
  if(ARG_MPI)
    separate_arguments(preflags NATIVE_COMMAND "${MPIEXEC_PREFLAGS}")
    separate_arguments(postflags NATIVE_COMMAND "${MPIEXEC_POSTFLAGS}")
    foreach(np IN LISTS ARG_RANKS)
      set(test_name ${suite}_np${np})
      set(workdir "${CMAKE_CURRENT_BINARY_DIR}/run/${test_name}")
      file(MAKE_DIRECTORY "${workdir}")
      add_test(NAME ${test_name}
               COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${preflags}
                       $<TARGET_FILE:${suite}> ${postflags}
               WORKING_DIRECTORY "${workdir}")
      set_tests_properties(${test_name} PROPERTIES
        PROCESSORS ${np}
        ENVIRONMENT "OMPI_MCA_rmaps_base_oversubscribe=1;OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_io=romio321"
        LABELS "${ARG_LABELS};mpi"
        TIMEOUT ${ARG_TIMEOUT})
    endforeach()
  else()
    set(workdir "${CMAKE_CURRENT_BINARY_DIR}/run/${suite}")
    file(MAKE_DIRECTORY "${workdir}")
    add_test(NAME ${suite} COMMAND $<TARGET_FILE:${suite}> WORKING_DIRECTORY "${workdir}")
    set_tests_properties(${suite} PROPERTIES
      PROCESSORS 1
      LABELS "${ARG_LABELS};serial"
      TIMEOUT ${ARG_TIMEOUT})
  endif()

  # --- optional: the same procedures as pFUnit tests --------------------------------------------
  get_property(have_pfunit GLOBAL PROPERTY FLOTSAM_HAVE_PFUNIT)
  if(have_pfunit)
    _flotsam_add_pfunit_wrapper()
  endif()
  flotsam_finish_folder_tests()
endfunction()

# Part of flotsam_add_test_suite (a macro, so it sees the caller's variables): writes
# <suite>_pfunit/pf_<suite>.pf with one @test per procedure and registers it with add_pfunit_ctest.
macro(_flotsam_add_pfunit_wrapper)
  set(FLOTSAM_PF_MODULE pf_${suite})
  set(FLOTSAM_PF_TESTS "")
  if(ARG_MPI)
    set(FLOTSAM_PF_FRAMEWORK pfunit)
    set(FLOTSAM_PF_EXTRA_USE "\n   use mpi_f08, only: MPI_Comm")
    list(JOIN ARG_RANKS ", " _pf_npes)
    list(SORT ARG_RANKS COMPARE NATURAL ORDER DESCENDING)
    list(GET ARG_RANKS 0 _pf_max_pes)
  else()
    set(FLOTSAM_PF_FRAMEWORK funit)
    set(FLOTSAM_PF_EXTRA_USE "")
  endif()
  foreach(test IN LISTS tests)
    set(_pf_check "      @assertEqual(failures_before, failure_count(), 'Flotsam assertions failed (FAIL lines above)')\n")
    if(ARG_MPI)
      string(APPEND FLOTSAM_PF_TESTS
        "\n   @test(npes=[${_pf_npes}])\n"
        "   subroutine pf_${test}(this)\n"
        "      class(MpiTestMethod), intent(inout) :: this\n"
        "      type(MPI_Comm) :: comm\n"
        "      integer :: failures_before\n"
        "      comm%MPI_VAL = this%getMpiCommunicator()\n"
        "      call set_current_test('${test}')\n"
        "      failures_before = failure_count()\n"
        "      call ${test}(comm)\n"
        "${_pf_check}"
        "   end subroutine pf_${test}\n")
    else()
      string(APPEND FLOTSAM_PF_TESTS
        "\n   @test\n"
        "   subroutine pf_${test}()\n"
        "      integer :: failures_before\n"
        "      call set_current_test('${test}')\n"
        "      failures_before = failure_count()\n"
        "      call ${test}()\n"
        "${_pf_check}"
        "   end subroutine pf_${test}\n")
    endif()
  endforeach()
  # Absolute path: add_pfunit_ctest then writes the processed .F90 next to it in the build tree.
  set(_pf_file "${CMAKE_CURRENT_BINARY_DIR}/${suite}_pfunit/${FLOTSAM_PF_MODULE}.pf")
  configure_file("${framework_dir}/pfunit_suite.pf.in" "${_pf_file}" @ONLY)
  set(_pf_workdir "${CMAKE_CURRENT_BINARY_DIR}/run/${suite}_pfunit")
  file(MAKE_DIRECTORY "${_pf_workdir}")
  if(ARG_MPI)
    add_pfunit_ctest(${suite}_pfunit TEST_SOURCES "${_pf_file}" LINK_LIBRARIES ${suite}_objects
                     MAX_PES ${_pf_max_pes} WORKING_DIRECTORY "${_pf_workdir}")
    set_tests_properties(${suite}_pfunit PROPERTIES PROCESSORS ${_pf_max_pes}
      ENVIRONMENT "OMPI_MCA_rmaps_base_oversubscribe=1;OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_io=romio321")
  else()
    add_pfunit_ctest(${suite}_pfunit TEST_SOURCES "${_pf_file}" LINK_LIBRARIES ${suite}_objects
                     WORKING_DIRECTORY "${_pf_workdir}")
  endif()
  set_tests_properties(${suite}_pfunit PROPERTIES LABELS "${ARG_LABELS};pfunit" TIMEOUT ${ARG_TIMEOUT})
endmacro()
