# tests/snapshots.cmake -- registers the tests of the offline-stage data (label snapshots):
#   training_set_np{1,2}    parameter samples: exact grids, ordering, LHS strata, seeded random,
#                           sample files and their errors (tests/test_training_set.cpp)
#   snapshot_file_np{1,2}   the HDF5 snapshot file: create, restart, header mismatch, garbage files,
#                           a writer killed mid-run (fork + _exit), snapshot-matrix import
#                           (tests/test_snapshot_file.cpp; scratch files under /tmp)
rbc_test_exe(test_training_set)
rbc_add_mpi_test(NAME training_set RANKS 1 2 TIMEOUT 120 COMMAND $<TARGET_FILE:test_training_set> LABELS snapshots)
rbc_test_exe(test_snapshot_file)
rbc_add_mpi_test(NAME snapshot_file RANKS 1 2 TIMEOUT 120 COMMAND $<TARGET_FILE:test_snapshot_file> LABELS snapshots)
