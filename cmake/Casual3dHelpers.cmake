# Small helpers so that every folder declares its targets the same way.
#
#   casual3d_add_library(NAME casual3d_foo SRCS a.cc b.cc DEPS casual3d_bar OpenCV::...)
#   casual3d_add_test(NAME foo_test SRCS foo_test.cc DEPS casual3d_foo [LABELS slow])
#
# Source lists are explicit (no file(GLOB)).

set(CASUAL3D_WARNINGS -Wall -Wextra -Wno-unused-parameter -Wno-sign-compare)

function(casual3d_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${ARG_NAME} STATIC ${ARG_SRCS})
  # Inside the tree, headers are included as "format/x.h"; installed ones carry
  # their own include directory (cmake/Casual3dSdk.cmake).
  target_include_directories(${ARG_NAME} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  target_link_libraries(${ARG_NAME} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_options(${ARG_NAME} PRIVATE ${CASUAL3D_WARNINGS})
endfunction()

# Registers a GoogleTest binary with ctest. Tests run from the build directory and
# find the source tree through the CASUAL3D_SOURCE_DIR environment variable.
function(casual3d_add_test)
  cmake_parse_arguments(ARG "" "NAME;TIMEOUT" "SRCS;DEPS;LABELS" ${ARGN})
  if(NOT CASUAL3D_BUILD_TESTS)
    return()
  endif()
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_options(${ARG_NAME} PRIVATE ${CASUAL3D_WARNINGS})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  add_test(NAME ${ARG_NAME} COMMAND ${ARG_NAME})
  set_tests_properties(${ARG_NAME} PROPERTIES
    TIMEOUT ${ARG_TIMEOUT}
    ENVIRONMENT "CASUAL3D_SOURCE_DIR=${PROJECT_SOURCE_DIR};CASUAL3D_BINARY_DIR=${PROJECT_BINARY_DIR}")
  if(ARG_LABELS)
    set_tests_properties(${ARG_NAME} PROPERTIES LABELS "${ARG_LABELS}")
  endif()
endfunction()
