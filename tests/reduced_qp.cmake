# tests/reduced_qp.cmake -- the online reduced QP (rbc::ReducedQP, tests/test_reduced_qp.cpp, docs/reduced_qp.md):
#   test_reduced_qp   active set vs TAO BQPIP, analytic case, warm starts, R > N (singular S), infeasible
#                     constraints, non-SPD A, iteration limit, no allocation in Solve after Reserve (serial)
rbc_test_exe(test_reduced_qp)
add_test(NAME test_reduced_qp COMMAND ${RBC_MPIEXEC} -n 1 $<TARGET_FILE:test_reduced_qp> WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(test_reduced_qp PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 120 PROCESSORS 1 LABELS rom)
