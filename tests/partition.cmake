# tests/partition.cmake -- registers the rbc::DistributeMesh tests (tests/test_partition.cpp)
# for our METIS shell partitioner and the partition by bodies (1, 2, 3 ranks) and PETSc's PT-Scotch
# partitioner (1, 2 ranks).
rbc_test_exe(test_partition)
rbc_add_mpi_test(NAME partition RANKS 1 2 3 COMMAND $<TARGET_FILE:test_partition> -mesh_partitioner metis)
rbc_add_mpi_test(NAME partition_bodies RANKS 1 2 3 COMMAND $<TARGET_FILE:test_partition> -mesh_partitioner bodies)
rbc_add_mpi_test(NAME partition_ptscotch RANKS 1 2 COMMAND $<TARGET_FILE:test_partition> -mesh_partitioner ptscotch)
