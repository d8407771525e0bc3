# tests/eim.cmake -- the Empirical Interpolation Method (src/reduction/eim.cpp, docs/eim.md), serial:
# the classical 1/sqrt((x-mu)^2+0.01) example (decay, history, hierarchy), the interpolation property,
# exactness on a 5-dimensional span, a LAPACK gesv cross-check, bad input and the eim options.
rbc_test_exe(test_eim)
rbc_add_mpi_test(NAME test_eim RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_eim> LABELS eim)
