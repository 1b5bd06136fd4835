# build/headform.ssp and build/bumper.ssp: the crash scenes (docs/scenes.md) as SSP
# 1.0, their SSD from ssp/ with the step of fraccontact/scenes/systems.py and
# their SSV files written from fraccontact/scenes/parameters.py, both by
# fraccontact.scenes.systems, with the FMUs of this build; the Python package
# ships them (SCENE_SSP_FILES).
set(scene_ssvs "${CMAKE_BINARY_DIR}/scenes_ssv")
file(GLOB scene_python "${CMAKE_SOURCE_DIR}/python/fraccontact/scenes/*.py")
add_custom_command(OUTPUT "${scene_ssvs}/stamp"
  COMMAND "${CMAKE_COMMAND}" -E rm -rf "${scene_ssvs}"
  # python -m finds the package in its working folder, first; PYTHONPATH is left as it is (pip's build
  # environment lives on it).
  COMMAND "${CMAKE_COMMAND}" -E env "FRACCONTACT_LIBRARY=$<TARGET_FILE:fraccontact_shared>" ${PYTHON_SANITIZER_ENV}
          "${Python3_EXECUTABLE}" -m fraccontact.scenes.systems "${scene_ssvs}" "${CMAKE_SOURCE_DIR}/ssp"
  COMMAND "${CMAKE_COMMAND}" -E touch "${scene_ssvs}/stamp"
  WORKING_DIRECTORY "${CMAKE_SOURCE_DIR}/python"
  DEPENDS ${scene_python} "${CMAKE_SOURCE_DIR}/ssp/headform.ssd" "${CMAKE_SOURCE_DIR}/ssp/bumper.ssd" fraccontact_shared
  COMMENT "Writing the scenes' SSV files and SSDs")
# One target runs it: two targets depending on one custom command's output would run it twice, at once.
add_custom_target(scene_ssvs DEPENDS "${scene_ssvs}/stamp")
set(SCENE_SSP_FILES "")
foreach(scene headform bumper)
  set(ssp_file "${CMAKE_BINARY_DIR}/${scene}.ssp")
  list(APPEND SCENE_SSP_FILES "${ssp_file}")
  set(staging "${CMAKE_BINARY_DIR}/${scene}.ssp.d")
  add_custom_command(OUTPUT "${ssp_file}"
    COMMAND "${CMAKE_COMMAND}" -E rm -rf "${staging}"
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${staging}/resources"
    COMMAND "${CMAKE_COMMAND}" -E copy "${scene_ssvs}/${scene}.ssd" "${staging}/SystemStructure.ssd"
    COMMAND "${CMAKE_COMMAND}" -E copy "${CMAKE_BINARY_DIR}/fraccontact.fmu" "${CMAKE_BINARY_DIR}/body.fmu"
            "${staging}/resources/"
    COMMAND sh -c "cp '${scene_ssvs}'/${scene}_*.ssv '${staging}/resources/'"
    COMMAND "${CMAKE_COMMAND}" -E rm -f "${ssp_file}"
    COMMAND "${CMAKE_COMMAND}" -E chdir "${staging}"
            "${CMAKE_COMMAND}" -E tar cf "${ssp_file}" --format=zip SystemStructure.ssd resources
    DEPENDS "${scene_ssvs}/stamp" "${CMAKE_BINARY_DIR}/fraccontact.fmu"
            "${CMAKE_BINARY_DIR}/body.fmu"
    COMMENT "Packaging ${scene}.ssp")
  add_custom_target(${scene}_ssp ALL DEPENDS "${ssp_file}")
  add_dependencies(${scene}_ssp fraccontact_fmu body_fmu scene_ssvs)
endforeach()
