# Fails the build when a source includes a folder its library does not
# declare as a dependency (CMake's PRIVATE links do not stop a static
# library's header-only or transitively linked use; this does).
#   cmake -DUNIT=pipelines/sfm -DALLOWED="colmap_ext;database;..." \
#         -DSOURCES="a.cc;b.h" -DSTAMP=out.stamp -P check_includes.cmake
# A unit is a top-level folder (colmap_ext, database, tools), a folder of
# pipelines/ (pipelines/sfm) or a test folder (tests/pipelines/sfm, whose
# ALLOWED are those of the libraries its test links). In pipelines/stages a
# stage includes no other stage unless it is one of COMPOSERS (the stages
# that run others: their file names without extension); the rest only run.
cmake_minimum_required(VERSION 3.18)
set(errors "")
foreach(source IN LISTS SOURCES)
  file(STRINGS "${source}" lines REGEX "^#include \"(colmap_ext|database|pipelines|tools)/")
  foreach(line IN LISTS lines)
    string(REGEX MATCH "\"([a-z_]+)/([a-z_]+)/?" match "${line}")
    set(top "${CMAKE_MATCH_1}")
    set(included "${top}")
    if(top STREQUAL "pipelines")
      set(included "pipelines/${CMAKE_MATCH_2}")
    endif()
    if(NOT included STREQUAL UNIT AND NOT included IN_LIST ALLOWED)
      string(APPEND errors "  ${source}: ${line}\n")
    elseif(UNIT STREQUAL "pipelines/stages" AND included STREQUAL UNIT)
      get_filename_component(stage "${source}" NAME_WE)
      string(REGEX MATCH "pipelines/stages/([a-z_]+)\\.h" other "${line}")
      if(NOT CMAKE_MATCH_1 STREQUAL stage AND NOT stage IN_LIST COMPOSERS)
        string(APPEND errors "  ${source}: ${line} (a stage that runs another is listed in PORTCAL_STAGE_COMPOSERS)\n")
      endif()
    endif()
  endforeach()
endforeach()
if(errors)
  message(FATAL_ERROR "${UNIT} may include only ${ALLOWED}; these includes break the layering "
                      "(declare the dependency in the library's CMakeLists.txt if it is right):\n${errors}")
endif()
file(WRITE "${STAMP}" "")
