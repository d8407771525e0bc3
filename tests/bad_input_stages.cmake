# tests/bad_input_stages.cmake -- bad input to the contact FOM, the offline stage and dualbasis: a
# clear error naming the option/value/file (tests/expect_error.sh: non-zero exit, message matches,
# no crash). Same runner as the bad_input tests of tests/elasticity.cmake.
set(RBC_EXPECT_ERROR_STAGE bash ${CMAKE_CURRENT_SOURCE_DIR}/expect_error.sh)
set(RBC_EXE_STAGE $<TARGET_FILE:rbcontact_exe>)
function(rbc_bad_stage name regex)
  add_test(NAME bad_input_${name} COMMAND ${RBC_EXPECT_ERROR_STAGE} "${regex}" ${RBC_EXE_STAGE} ${ARGN} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(bad_input_${name} PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 120 LABELS bad_input)
endfunction()
rbc_bad_stage(mu_outside_box "-mu: parameter 'radius' = 1.3 is outside its box" fom -options_file runs/ring_on_block.opts -mu 1.3)
rbc_bad_stage(contact_quadrature "-contact_quadrature: unknown value 'bogus'" fom -options_file runs/ring_on_block.opts -contact_quadrature bogus)
rbc_bad_stage(kacanov_not_converged "Kacanov iterations did not converge in 2 iterations.*History" fom -options_file runs/ring_on_block.opts -kacanov_max_it 2)
rbc_bad_stage(offline_stop "-offline_stop eim: unknown step" offline -options_file runs/ring_on_block.opts -offline_stop eim -snapshots /tmp/rbc_never.h5)
rbc_bad_stage(offline_no_snapshot_file "give the snapshot file with -snapshots" offline -options_file runs/ring_on_block.opts -offline_stop snapshots)
rbc_bad_stage(snapshots_subcomm "-snapshots_subcomm 3 must lie in [[]1, 1[]]" offline -options_file runs/ring_on_block.opts -offline_stop snapshots -snapshots /tmp/rbc_never.h5 -snapshots_subcomm 3)
rbc_bad_stage(dual_type "bogus" dualbasis -snapshots meshes/nosuch.h5:/x -dual_type bogus)
rbc_bad_stage(dualbasis_missing_file "nosuch[.]h5" dualbasis -snapshots nosuch.h5:/lambda)
