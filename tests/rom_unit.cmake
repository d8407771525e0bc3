# tests/rom_unit.cmake -- unit checks of the reduced model's building blocks against the full-order code:
#   test_reduced_contact   ContactPatch (full patch = FOM contact map with the composite rule, Restrict,
#                          serialization) and ReducedParametrization (thetas, ROM-file roundtrip, CheckBox)
rbc_test_exe(test_reduced_contact)
rbc_add_mpi_test(NAME reduced_contact RANKS 1 2 TIMEOUT 120 COMMAND $<TARGET_FILE:test_reduced_contact> -options_file runs/ring_on_block.opts LABELS rom)
#   test_anderson          Anderson mixing of the reduced Kacanov loop (-rom_kacanov_anderson): fixed point vs
#                          a LAPACK solve, iteration counts vs the plain iteration, the restart safeguard
rbc_test_exe(test_anderson)
rbc_add_mpi_test(NAME test_anderson RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_anderson> LABELS rom)
#   test_kacanov_loop      the Kacanov loop shared by the FOM and the ROM (KacanovLoop): fixed point vs LAPACK,
#                          Anderson, relaxation, the linearized max_it 1, the not-converged message, the options
rbc_test_exe(test_kacanov_loop)
rbc_add_mpi_test(NAME test_kacanov_loop RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_kacanov_loop> LABELS rom)
#   test_warm_start        the online warm start's weights (WarmStartWeights): the bracketing interpolation with one
#                          parameter, affine data reproduced and second order with 2 and 3, the collinear fallback
rbc_test_exe(test_warm_start)
rbc_add_mpi_test(NAME test_warm_start RANKS 1 2 TIMEOUT 60 COMMAND $<TARGET_FILE:test_warm_start> LABELS rom)
#   test_supremizers       the compressed supremizer enrichment (EnrichWithSupremizers, -pod_supremizers_infsup) on a
#                          synthetic saddle point: orthonormal basis holding the POD modes, every reported inf-sup
#                          constant recomputed from the returned basis, the full enrichment spans every supremizer
rbc_test_exe(test_supremizers)
rbc_add_mpi_test(NAME test_supremizers RANKS 1 2 TIMEOUT 60 COMMAND $<TARGET_FILE:test_supremizers> LABELS rom)
#   test_empirical_cubature  the ECSW fit (-rom_hyper ecsw): Gram matrix vs explicit rows, Caratheodory bound on
#                          moments, nonnegative weights, the reported residual recomputed from the fitted terms
rbc_test_exe(test_empirical_cubature)
rbc_add_mpi_test(NAME test_empirical_cubature RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_empirical_cubature> LABELS rom)
#   test_dense_kernels     the online contact kernels (SumOfOuterProducts, CombineRows, ScatterRows, RowDots, the QP set-up; AVX2+FMA where the CPU has
#                          it) against plain loops, at sizes around the register blocking
rbc_test_exe(test_dense_kernels)
rbc_add_mpi_test(NAME test_dense_kernels RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_dense_kernels> LABELS rom)
rbc_add_mpi_test(NAME test_dense_kernels_portable RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_dense_kernels> LABELS rom)
set_property(TEST test_dense_kernels_portable_np1 APPEND PROPERTY ENVIRONMENT RBC_KERNELS_PORTABLE=1)
#   test_greedy_indicator  the greedy training's indicator (GreedyIndicator) against the FOM: zero at the converged
#                          contact solution (two radii), ||e||_X / ||u + e||_X for a perturbation off the contact
#                          surfaces, the penetration of 1.2 u; GreedyPick's order and separation
rbc_test_exe(test_greedy_indicator)
rbc_add_mpi_test(NAME test_greedy_indicator RANKS 1 2 TIMEOUT 120 COMMAND $<TARGET_FILE:test_greedy_indicator> -options_file runs/ring_on_block.opts LABELS rom)
#   test_error_estimate    the calibration of the online error estimate (CalibrateEstimate): proportional data give
#                          their factor, uninformative data the floor, every point covered, the best scale of a
#                          brute-force search
rbc_test_exe(test_error_estimate)
rbc_add_mpi_test(NAME test_error_estimate RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_error_estimate> LABELS rom)
#   test_dual_selection    the offline choice of the answer's dual vectors on held-out solutions (ChooseDualSize,
#                          DualSelectionCandidates) on hand-made tables, the finest 3D level's among them
rbc_test_exe(test_dual_selection)
rbc_add_mpi_test(NAME test_dual_selection RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_dual_selection> LABELS rom)
#   test_fork_join         the thread pool of -rom_threads (ForkJoin): every part once on its own thread over many
#                          regions, late workers, Part's ranges, and the CPUs (the caller's mask, the workers' SetCpus)
rbc_test_exe(test_fork_join)
rbc_add_mpi_test(NAME test_fork_join RANKS 1 TIMEOUT 60 COMMAND $<TARGET_FILE:test_fork_join> LABELS rom)
#   test_rom_contact_terms the public ContactTerms with A^ diagonalized once and the points' sum in float (its rows
#                          theta V) against the same model without: run by rom_checks.py sphere_block3d on its ROM
rbc_test_exe(test_rom_contact_terms)
#   test_model_api         the C++ API's ReducedModel used out of order: no model (default-constructed, or after a
#                          failed Open) refused by Solve, SetFromOptions and Truncate, naming the cause
rbc_test_exe(test_model_api)
rbc_add_mpi_test(NAME test_model_api RANKS 1 TIMEOUT 120 COMMAND $<TARGET_FILE:test_model_api> -options_file runs/ring_on_block.opts LABELS rom)
