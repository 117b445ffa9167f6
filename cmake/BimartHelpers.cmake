# Helpers so that every CMakeLists.txt in the tree is a few declarative lines.
# This file is installed with the package: out-of-tree plug-ins use bimart_add_plugin too.

# bimart_add_plugin(NAME SOURCES a.cc b.cc [LIBRARIES lib ...] [OUTPUT_DIRECTORY dir])
# Builds a plug-in library `bimart_<NAME>`: a shared library linked against the core and
# the entry points (bimart::plugin_entry), with hidden symbols, loadable by the host.
# In the bimart tree it lands in the built-in plug-in folder and is installed there.
function(bimart_add_plugin name)
  cmake_parse_arguments(ARG "" "OUTPUT_DIRECTORY" "SOURCES;LIBRARIES" ${ARGN})
  set(target bimart_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE bimart::core bimart::plugin_entry ${ARG_LIBRARIES})
  set_target_properties(${target} PROPERTIES PREFIX "lib" CXX_VISIBILITY_PRESET hidden
                                             VISIBILITY_INLINES_HIDDEN ON)
  if(ARG_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  elseif(BIMART_PLUGIN_OUTPUT_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${BIMART_PLUGIN_OUTPUT_DIR}
                                               INSTALL_RPATH "$ORIGIN/../..;${BIMART_OPENBLAS_DIR}")
    install(TARGETS ${target} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/bimart/plugins)
    set_property(GLOBAL APPEND PROPERTY BIMART_BUILTIN_PLUGINS ${target})
  endif()
endfunction()

# bimart_add_test(NAME SOURCES a.cc ... [LIBRARIES lib ...] [LABELS label ...])
# A GoogleTest executable registered with ctest as one test: every process pays for loading
# libtorch (~0.8 s), so one entry per executable rather than per test case.
function(bimart_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBRARIES;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE bimart::core bimart_test_main ${ARG_LIBRARIES})
  add_test(NAME ${name} COMMAND ${name} --gtest_color=no)
  set_tests_properties(${name} PROPERTIES LABELS "unit;${ARG_LABELS}")
endfunction()
