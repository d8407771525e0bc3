# tests/rom.cmake -- the ROM pipeline: offline -> ROM file -> online / validate (tests/rom_checks.py).
find_program(RBC_PYTHON3_ROM NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
foreach(t pipeline bad_input infeasible half_disks eim_train eim_select files sphere_block3d residual estimate dual_select dual_refit probe guards p2 supremizer_noise)
  add_test(NAME rom_${t} COMMAND ${RBC_PYTHON3_ROM} ${CMAKE_CURRENT_SOURCE_DIR}/rom_checks.py ${t} --exe $<TARGET_FILE:rbcontact_exe> --contact-terms-exe $<TARGET_FILE:test_rom_contact_terms> WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(rom_${t} PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 600 PROCESSORS 2 LABELS rom)
endforeach()
