# tests/dual_basis.cmake -- the dual (multiplier) bases and their NNLS cone projections:
# NNLSSolver against an independent QR Lawson-Hanson, and nmf/angle/cpg/mcpg on synthetic Hertz-like
# snapshots (nonnegativity, monotone greedy history, tolerance, determinism, 1 vs 2 ranks).
rbc_test_exe(test_nnls)
rbc_add_mpi_test(NAME nnls RANKS 1 2 COMMAND $<TARGET_FILE:test_nnls> LABELS dual_basis)
rbc_test_exe(test_dual_basis)
rbc_add_mpi_test(NAME dual_basis RANKS 1 2 COMMAND $<TARGET_FILE:test_dual_basis> LABELS dual_basis)
