# docs/SDK.md shows code from the tested examples: every ```cpp, ```cmake and
# ```make block must appear verbatim in one of the files under examples/cpp.
#
#   cmake -DSOURCE_DIR=<repository> -P doc_snippets_test.cmake

cmake_minimum_required(VERSION 3.22)
set(doc ${SOURCE_DIR}/docs/SDK.md)
set(examples
  ${SOURCE_DIR}/examples/cpp/casual3d_example.cc
  ${SOURCE_DIR}/examples/cpp/CMakeLists.txt
  ${SOURCE_DIR}/examples/cpp/pkg-config/manifest_info.cc
  ${SOURCE_DIR}/examples/cpp/pkg-config/Makefile)
set(sources "")
foreach(f ${examples})
  file(READ ${f} text)
  string(APPEND sources "${text}\n")
endforeach()

file(STRINGS ${doc} lines)
set(in_block FALSE)
set(checked 0)
set(line_number 0)
foreach(line IN LISTS lines)
  math(EXPR line_number "${line_number} + 1")
  if(NOT in_block AND line MATCHES "^```(cpp|cmake|make)$")
    set(in_block TRUE)
    set(block "")
    set(block_start ${line_number})
  elseif(in_block AND line STREQUAL "```")
    set(in_block FALSE)
    string(FIND "${sources}" "${block}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "docs/SDK.md:${block_start}: this code block is not in examples/cpp "
                          "(copy it from the example, which the sdk tests build and run):\n${block}")
    endif()
    math(EXPR checked "${checked} + 1")
  elseif(in_block)
    string(APPEND block "${line}\n")
  endif()
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "docs/SDK.md: no cpp, cmake or make code blocks found")
endif()
message(STATUS "docs/SDK.md: ${checked} code blocks found in examples/cpp")
