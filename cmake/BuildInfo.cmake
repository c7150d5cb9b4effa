# Writes the build facts module (src/common/build_info.f90.in -> OUTPUT) at every build, so the git
# commit a binary reports is the one it was built from, not the one CMake last configured at.
# configure_file rewrites OUTPUT only when its text changes: an unchanged commit rebuilds nothing.
# Run with: cmake -DSOURCE_DIR=... -DINPUT=... -DOUTPUT=... -DPROJECT_VERSION=... -P BuildInfo.cmake
set(FLOTSAM_GIT_COMMIT "unknown")
find_package(Git QUIET)
if(GIT_FOUND AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT_EXECUTABLE}" rev-parse --short=12 HEAD
                  WORKING_DIRECTORY "${SOURCE_DIR}" OUTPUT_VARIABLE _commit
                  RESULT_VARIABLE _result OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(_result EQUAL 0 AND _commit)
    set(FLOTSAM_GIT_COMMIT "${_commit}")
    # tracked files changed since that commit: the binary is not exactly the commit
    execute_process(COMMAND "${GIT_EXECUTABLE}" diff --quiet HEAD -- src CMakeLists.txt cmake
                    WORKING_DIRECTORY "${SOURCE_DIR}" RESULT_VARIABLE _dirty ERROR_QUIET)
    if(NOT _dirty EQUAL 0)
      string(APPEND FLOTSAM_GIT_COMMIT "-modified")
    endif()
  endif()
endif()
configure_file("${INPUT}" "${OUTPUT}" @ONLY)
