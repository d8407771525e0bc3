# tests/offline.cmake -- the offline snapshot stage: 1 vs 2 ranks (2 subcommunicators), 2 parameters,
# kill and resume, mismatched files, greedy training, training sets extended by -snapshots_from, sensitivity snapshots,
# the nearest snapshot as the initial guess, a full disk.
find_program(RBC_PYTHON3_OFF NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
foreach(t ring half_disks resume concurrent mismatch early_options bases_warnings bases dualbasis_import greedy snapshots_from sensitivities initial_guess disk_full)
  add_test(NAME offline_${t} COMMAND ${RBC_PYTHON3_OFF} ${CMAKE_CURRENT_SOURCE_DIR}/offline_checks.py ${t} --exe $<TARGET_FILE:rbcontact_exe> WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(offline_${t} PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 600 PROCESSORS 2 LABELS offline)
endforeach()
# disk_full mounts a 4 MB tmpfs (root only): where it cannot, the script exits 77 and the test is reported as skipped
set_tests_properties(offline_disk_full PROPERTIES SKIP_RETURN_CODE 77)
