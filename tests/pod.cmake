# tests/pod.cmake -- registers the tests of the POD (label pod; tests/test_pod.cpp, docs/pod.md):
#   pod_np{1,2}          a) synthetic M-weighted POD vs a dense LAPACK reference, -pod_tol/-pod_n,
#                        projection identity; b) energy POD of ring_on_block FOM snapshots;
#                        c) -pod_method svd vs the BV path (l2); d) writes checksums and the FOM's
#                        singular values (-pod_sv_out) to pod_{checksums,sv}_np{1,2}.txt
#   pod_compare_sv       the FOM singular values on 1 and 2 ranks agree (|a^2 - b^2| <= 1e-12 a_0^2)
#   pod_compare_modes    the checksums of the modes with s_i >= 1e-2 s_0 (synthetic: w.v_i and s_i;
#                        FOM: sum(v_i), |v_i|_2) on 1 and 2 ranks agree to 1e-10 relative
rbc_test_exe(test_pod)
set(RBC_POD_SCENE -options_file runs/ring_on_block.opts -contact 0 -dirichlet ring_top,block_bottom,slave -dirichlet_slave_u 0,0 -dirichlet_ring_top_u 0.01,-0.05)
set(RBC_POD_OUT ${CMAKE_CURRENT_BINARY_DIR})
foreach(np 1 2)
  rbc_add_mpi_test(NAME pod RANKS ${np} TIMEOUT 300 COMMAND $<TARGET_FILE:test_pod> ${RBC_POD_SCENE}
    -test_out ${RBC_POD_OUT}/pod_checksums_np${np}.txt -test_sv_out ${RBC_POD_OUT}/pod_sv_np${np}.txt LABELS pod)
  set_tests_properties(pod_np${np} PROPERTIES FIXTURES_SETUP pod_out_np${np})
endforeach()
rbc_add_mpi_test(NAME pod_compare_sv RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_pod>
  -compare ${RBC_POD_OUT}/pod_sv_np1.txt,${RBC_POD_OUT}/pod_sv_np2.txt -compare_mode sv -compare_tol 1e-12 LABELS pod)
rbc_add_mpi_test(NAME pod_compare_modes RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_pod>
  -compare ${RBC_POD_OUT}/pod_checksums_np1.txt,${RBC_POD_OUT}/pod_checksums_np2.txt -compare_mode rel -compare_tol 1e-10 LABELS pod)
set_tests_properties(pod_compare_sv_np1 pod_compare_modes_np1 PROPERTIES FIXTURES_REQUIRED "pod_out_np1;pod_out_np2")

# Bad pod_ options: a clear message naming the option and value (tests/expect_error.sh).
set(RBC_POD_EXPECT_ERROR bash ${CMAKE_CURRENT_SOURCE_DIR}/expect_error.sh)
# Registered without an mpiexec around the script (an MPI_Abort of the singleton test_pod inside it
# made the outer mpiexec fail now and then); test_pod runs as an MPI singleton.
function(rbc_pod_bad name regex)
  add_test(NAME pod_bad_${name} COMMAND ${RBC_POD_EXPECT_ERROR} "${regex}" $<TARGET_FILE:test_pod> -test_parts a ${ARGN}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(pod_bad_${name} PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 60 LABELS pod)
endfunction()
rbc_pod_bad(n "-pod_n 0 must lie in \\[1, 20\\] [(]the number of snapshots[)]" -pod_n 0)
rbc_pod_bad(tol "-pod_tol 1[.]5 must lie in \\[0, 1[)]" -pod_tol 1.5)
rbc_pod_bad(method_svd_with_M "-pod_method svd computes the l2 POD only" -pod_method svd)
rbc_pod_bad(method "Unknown option bogus for -pod_method" -pod_method bogus)
rbc_pod_bad(sv_out "-pod_sv_out /nonexistent/dir/sv[.]txt: cannot write the file" -pod_sv_out /nonexistent/dir/sv.txt)
