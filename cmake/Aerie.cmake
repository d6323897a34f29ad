# Helpers that give every Aerie target the same shape (ARCHITECTURE.md):
# a library per component (the algorithm, no LCM unless it is a bus helper) and
# thin executables around it. Includes are rooted at the repository top:
#   #include "common/geometry/se3.hpp"

add_library(aerie_warnings INTERFACE)
target_compile_options(aerie_warnings INTERFACE -Wall -Wextra -Wpedantic
  $<$<BOOL:${AERIE_WERROR}>:-Werror>)

# aerie_library(NAME SOURCES ... [PUBLIC deps...] [PRIVATE deps...])
function(aerie_library name)
  cmake_parse_arguments(A "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  if(A_SOURCES)
    add_library(${name} STATIC ${A_SOURCES})
    target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} PUBLIC ${A_PUBLIC} PRIVATE aerie_warnings ${A_PRIVATE})
  else()
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} INTERFACE ${A_PUBLIC})
  endif()
endfunction()

# aerie_executable(NAME SOURCES ... [LIBS deps...]) -> installed in bin/
function(aerie_executable name)
  cmake_parse_arguments(A "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  target_link_libraries(${name} PRIVATE aerie_warnings ${A_LIBS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
  install(TARGETS ${name} RUNTIME DESTINATION bin)
endfunction()

# aerie_test(NAME SOURCES ... [LIBS deps...] [LABELS l...] [TIMEOUT s] [XVFB] [SERIAL])
# A GoogleTest executable; its tests are discovered at test time so that ctest
# runs and reports each TEST separately. XVFB runs it under `xvfb-run -a`
# (off-screen rendering); SERIAL keeps it from running beside other tests.
# Discovered tests get their properties from a script ctest includes after
# discovery: passed through gtest_discover_tests(PROPERTIES), two LABELS lose
# their separator and shift every property after them (RUN_SERIAL was silently
# dropped that way).
function(aerie_test name)
  cmake_parse_arguments(A "XVFB;SERIAL" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  target_link_libraries(${name} PRIVATE aerie_warnings aerie_test_support GTest::gtest_main
                        ${A_LIBS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 300)
  endif()
  if(A_XVFB)
    find_program(XVFB_RUN xvfb-run REQUIRED)
    # -noreset: by default Xvfb resets when its last client disconnects, and a client that
    # connects meanwhile (the next test's render window) gets no display ("bad X server
    # connection"; 1 run of test_viewer in 6 on a loaded machine).
    add_test(NAME ${name} COMMAND ${XVFB_RUN} -a -s "-screen 0 1280x1024x24 -noreset" $<TARGET_FILE:${name}>)
    # Two `xvfb-run -a` starting at once can both take display :99 and one's server then
    # goes with the other's (test_viewer lost its X server that way under ctest -j2): every
    # test that starts xvfb-run holds this lock.
    set_tests_properties(${name} PROPERTIES TIMEOUT ${A_TIMEOUT} RUN_SERIAL ${A_SERIAL} LABELS "${A_LABELS}"
                                            RESOURCE_LOCK xvfb-run)
  else()
    gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60 TEST_LIST ${name}_TESTS)
    set(script ${CMAKE_CURRENT_BINARY_DIR}/${name}_properties.cmake)
    file(WRITE ${script} "set_tests_properties(\${${name}_TESTS} PROPERTIES TIMEOUT ${A_TIMEOUT} "
                         "RUN_SERIAL ${A_SERIAL} LABELS \"${A_LABELS}\")\n")
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${script})
  endif()
endfunction()

# Adds every immediate subfolder that has a CMakeLists.txt, so a new component
# needs no edit of its parent.
function(aerie_add_subdirectories)
  file(GLOB children LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR}
       CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*)
  list(SORT children)
  foreach(child ${children})
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${child}/CMakeLists.txt)
      add_subdirectory(${child})
    endif()
  endforeach()
endfunction()
