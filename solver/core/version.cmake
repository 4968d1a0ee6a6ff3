# Writes version.hpp at build time (not configure time), so that a binary names the commit it was
# built from, with "-dirty" when the working tree had uncommitted changes. configure_file leaves the
# file untouched when nothing changed, so an unchanged revision rebuilds nothing.
#   cmake -DSRC=<source root> -DIN=<version.hpp.in> -DOUT=<version.hpp> -DBOYCOTT_VERSION=<x.y.z> -P version.cmake
execute_process(COMMAND git rev-parse --short HEAD WORKING_DIRECTORY ${SRC}
                OUTPUT_VARIABLE BOYCOTT_GIT OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT BOYCOTT_GIT)
  set(BOYCOTT_GIT "unknown")
else()
  execute_process(COMMAND git status --porcelain --untracked-files=no WORKING_DIRECTORY ${SRC}
                  OUTPUT_VARIABLE dirty OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(dirty)
    string(APPEND BOYCOTT_GIT "-dirty")
  endif()
endif()
configure_file(${IN} ${OUT} @ONLY)
