# Run at every build (packaging/packaging.cmake): writes OUT from build_info.cpp.in with the
# project's version and, when the source is a git checkout, `git describe`. configure_file
# rewrites OUT only when its text changes, so an unchanged checkout relinks nothing.
set(GIT_DESCRIBE "")
find_program(GIT git)
if(GIT AND EXISTS ${SOURCE_DIR}/.git)
  execute_process(COMMAND ${GIT} -C ${SOURCE_DIR} describe --always --dirty --tags
    OUTPUT_VARIABLE GIT_DESCRIBE OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    set(GIT_DESCRIBE "")
  endif()
endif()
configure_file(${CMAKE_CURRENT_LIST_DIR}/build_info.cpp.in ${OUT} @ONLY)
