# portcal_layering(TARGET UNIT FOLDER ALLOWED...): before TARGET builds,
# check that the sources and headers in FOLDER include only UNIT itself and
# the ALLOWED units (see check_includes.cmake). TARGET keeps UNIT and
# ALLOWED as properties, for the tests that link it (portcal_add_test).
function(portcal_layering target unit folder)
  file(GLOB files CONFIGURE_DEPENDS "${folder}/*.h" "${folder}/*.cc" "${folder}/*/*.h" "${folder}/*/*.cc")
  set_target_properties(${target} PROPERTIES PORTCAL_UNIT "${unit}" PORTCAL_ALLOWED "${ARGN}")
  portcal_check_includes(${target} ${unit} "${files}" ${ARGN})
endfunction()

# portcal_check_includes(TARGET UNIT FILES ALLOWED...): the same check on a
# list of files.
function(portcal_check_includes target unit files)
  string(MAKE_C_IDENTIFIER "${target}" stamp_name)
  set(stamp "${CMAKE_CURRENT_BINARY_DIR}/${stamp_name}_layering.stamp")
  add_custom_command(OUTPUT "${stamp}"
    COMMAND ${CMAKE_COMMAND} "-DUNIT=${unit}" "-DALLOWED=${ARGN}" "-DSOURCES=${files}"
            "-DCOMPOSERS=${PORTCAL_STAGE_COMPOSERS}"
            "-DSTAMP=${stamp}" -P "${PROJECT_SOURCE_DIR}/cmake/check_includes.cmake"
    DEPENDS ${files} "${PROJECT_SOURCE_DIR}/cmake/check_includes.cmake"
    COMMENT "Checking ${unit}'s includes against its declared dependencies"
    VERBATIM)
  add_custom_target(${target}_layering DEPENDS "${stamp}")
  add_dependencies(${target} ${target}_layering)
endfunction()
