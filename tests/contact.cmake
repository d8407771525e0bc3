# tests/contact.cmake -- the contact full-order model: Hertz, flat-punch patch test (2D and 3D), no-contact gap,
# ring on block (convergence, 1 vs 2 ranks), KKT on every scene, the dense QP solvers, the matrix-free
# dual (-fom_dual_matrix shell) and the saddle-point active set (-fom_dual_matrix saddle) against the dense one, the fast FOM path against the reference settings,
# the compliance methods against each other, the mortar segment search against the full search, the Newton
# Kacanov step against the fixed point (test_kacanov_newton).
find_program(RBC_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
set(RBC_CC ${RBC_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/contact_checks.py)
foreach(np 1 2)
  add_test(NAME contact_hertz_np${np} COMMAND ${RBC_CC} hertz --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_flat_punch_np${np} COMMAND ${RBC_CC} flat_punch --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_no_contact_np${np} COMMAND ${RBC_CC} no_contact --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_kkt_all_np${np} COMMAND ${RBC_CC} kkt_all --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_dual_shell_np${np} COMMAND ${RBC_CC} dual_shell --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_saddle_np${np} COMMAND ${RBC_CC} saddle --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_smooth_np${np} COMMAND ${RBC_CC} smooth --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_nan_input_np${np} COMMAND ${RBC_CC} nan_input --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_floating_np${np} COMMAND ${RBC_CC} floating --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_warnings_np${np} COMMAND ${RBC_CC} warnings --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_paths_np${np} COMMAND ${RBC_CC} paths --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_compliance_np${np} COMMAND ${RBC_CC} compliance --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_segments_np${np} COMMAND ${RBC_CC} segments --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_flat_punch3d_np${np} COMMAND ${RBC_CC} flat_punch3d --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_search_np${np} COMMAND ${RBC_CC} search --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_solver_input_np${np} COMMAND ${RBC_CC} solver_input --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_solver_options_np${np} COMMAND ${RBC_CC} solver_options --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME contact_diagnoses_np${np} COMMAND ${RBC_CC} diagnoses --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(contact_diagnoses_np${np} contact_solver_options_np${np} contact_solver_input_np${np} contact_search_np${np} contact_hertz_np${np} contact_flat_punch_np${np} contact_no_contact_np${np} contact_kkt_all_np${np} contact_dual_shell_np${np} contact_saddle_np${np} contact_smooth_np${np} contact_nan_input_np${np} contact_floating_np${np} contact_warnings_np${np} contact_paths_np${np} contact_compliance_np${np} contact_segments_np${np} contact_flat_punch3d_np${np}
    PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 600 PROCESSORS ${np} LABELS contact)
endforeach()
# runs both rank counts itself and compares them
add_test(NAME contact_hertz3d_np1_np2 COMMAND ${RBC_CC} hertz3d --exe $<TARGET_FILE:rbcontact_exe> WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(contact_hertz3d_np1_np2 PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 600 PROCESSORS 2 LABELS contact)
add_test(NAME contact_partition_np1_np2 COMMAND ${RBC_CC} partition --exe $<TARGET_FILE:rbcontact_exe> WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
add_test(NAME contact_ring_np1_np2 COMMAND ${RBC_CC} ring --exe $<TARGET_FILE:rbcontact_exe> WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(contact_ring_np1_np2 contact_partition_np1_np2 PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 600 PROCESSORS 2 LABELS contact)

rbc_test_exe(test_bound_qp)
rbc_add_mpi_test(NAME bound_qp RANKS 1 COMMAND $<TARGET_FILE:test_bound_qp> LABELS contact)
rbc_test_exe(test_closest_point)
rbc_add_mpi_test(NAME closest_point RANKS 1 COMMAND $<TARGET_FILE:test_closest_point> LABELS contact)
# -kacanov_type newton against fixed_point (iterations, force) and the contact tangent against finite differences
rbc_test_exe(test_kacanov_newton)
rbc_add_mpi_test(NAME kacanov_newton_half_disks RANKS 1 2 COMMAND $<TARGET_FILE:test_kacanov_newton> -options_file runs/half_disks.opts -test_max_its 7 LABELS contact)
rbc_add_mpi_test(NAME kacanov_newton_ring RANKS 1 2 COMMAND $<TARGET_FILE:test_kacanov_newton> -options_file runs/ring_on_block.opts -test_max_its 7 LABELS contact)
rbc_add_mpi_test(NAME kacanov_newton_hertz RANKS 1 2 COMMAND $<TARGET_FILE:test_kacanov_newton> -options_file runs/hertz.opts -test_max_its 7 LABELS contact)
