# Copies the public headers into an include tree for installation, with their
# includes of each other rewritten from "format/x.h" to "casual3d/format/x.h",
# so that users put only <prefix>/include on their include path and a library
# of their own with a format/ folder cannot clash with ours.
#
#   cmake -DHEADERS="format/a.h;encoder/b.h" -DSEARCH_DIRS="src;gen" -DOUTPUT_DIR=out
#         -P Casual3dStageHeaders.cmake
#
# HEADERS: the public headers, relative to one of SEARCH_DIRS (first match
# wins). A public header that includes a project header outside HEADERS is an
# error: it would not compile once installed.

cmake_minimum_required(VERSION 3.22)

foreach(var HEADERS SEARCH_DIRS OUTPUT_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "Casual3dStageHeaders.cmake: pass -D${var}=...")
  endif()
endforeach()

foreach(header ${HEADERS})
  set(source "")
  foreach(dir ${SEARCH_DIRS})
    if(EXISTS "${dir}/${header}")
      set(source "${dir}/${header}")
      break()
    endif()
  endforeach()
  if(NOT source)
    message(FATAL_ERROR "${header}: public header not found in ${SEARCH_DIRS}")
  endif()

  file(STRINGS "${source}" included REGEX "^#include \"")
  foreach(line ${included})
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" name "${line}")
    if(NOT name IN_LIST HEADERS)
      message(FATAL_ERROR "${header} is public but includes ${name}, which is not: "
                          "list ${name} among the public headers in cmake/Casual3dSdk.cmake "
                          "or move the include into a .cc file")
    endif()
  endforeach()

  file(READ "${source}" text)
  string(REGEX REPLACE "\n#include \"([a-z]+/)" "\n#include \"casual3d/\\1" text "${text}")
  file(WRITE "${OUTPUT_DIR}/casual3d/${header}" "${text}")
endforeach()
