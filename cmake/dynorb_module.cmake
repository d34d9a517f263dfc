# Helpers shared by every module's CMakeLists.txt.

set(DYNORB_WARNINGS -Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor -Wno-deprecated-enum-enum-conversion)
if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")  # the fuzz preset; clang has no -Wshadow=local
  list(REMOVE_ITEM DYNORB_WARNINGS -Wshadow=local)
endif()

if(DYNORB_SANITIZE)
  add_compile_options(-fsanitize=${DYNORB_SANITIZE} -fno-omit-frame-pointer)
  add_link_options(-fsanitize=${DYNORB_SANITIZE})
endif()

# dynorb_add_module(NAME SOURCES a.cc b.cc DEPS dynorb_core OpenCV...)
# Creates static library dynorb_<NAME>; headers are included as "dynorb/<NAME>/x.h".
function(dynorb_add_module NAME)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(dynorb_${NAME} STATIC ${ARG_SOURCES})
  target_include_directories(dynorb_${NAME} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(dynorb_${NAME} PUBLIC ${ARG_DEPS})
  target_compile_options(dynorb_${NAME} PRIVATE ${DYNORB_WARNINGS})
endfunction()

# dynorb_add_test(NAME SOURCES a_test.cc DEPS dynorb_x)
# One GoogleTest executable per module: dynorb_<NAME>_test, registered with CTest.
function(dynorb_add_test NAME)
  if(NOT DYNORB_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(dynorb_${NAME}_test ${ARG_SOURCES})
  target_link_libraries(dynorb_${NAME}_test PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main
                        GTest::gmock)
  target_compile_options(dynorb_${NAME}_test PRIVATE ${DYNORB_WARNINGS})
  target_compile_definitions(dynorb_${NAME}_test PRIVATE
    DYNORB_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    DYNORB_SHARED_DIR="${PROJECT_SOURCE_DIR}/../shared")
  gtest_discover_tests(dynorb_${NAME}_test DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT "DYNORB_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endfunction()
