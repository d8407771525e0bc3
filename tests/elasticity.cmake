# tests/elasticity.cmake -- registers the tests of the elastic full-order model (label elasticity):
#   mms_np{1,2}              manufactured solutions, 2D/3D, P1/P2, L2 rates (tests/test_mms.cpp)
#   vonmises_np{1,2}         uniform-strain patch: cell von Mises == analytic; HDF5/XDMF output
#   two_bodies_np{1,2}       two disconnected bodies == two one-body solves (DMPlexFilter)
#   fom_parallel_*           parallel energy == serial energy on rank 0 (metis np1/np2, ptscotch,
#                            P2, CG+GAMG vs MUMPS)
#   bad_input_*              `rbcontact fom` on bad input must fail with a clear message
#                            (tests/expect_error.sh REGEX cmd...: non-zero exit, message matches,
#                            no crash / NaN in the output)
rbc_test_exe(test_mms)
rbc_add_mpi_test(NAME mms RANKS 1 2 COMMAND $<TARGET_FILE:test_mms> LABELS elasticity)
rbc_test_exe(test_vonmises)
rbc_add_mpi_test(NAME vonmises RANKS 1 2 COMMAND $<TARGET_FILE:test_vonmises> -out_dir ${CMAKE_CURRENT_BINARY_DIR} LABELS elasticity)
rbc_test_exe(test_two_bodies)
rbc_add_mpi_test(NAME two_bodies RANKS 1 2 COMMAND $<TARGET_FILE:test_two_bodies> LABELS elasticity)

# Ring on block without contact, the slave arc clamped and the ring top moved: a stressed scene.
rbc_test_exe(test_fom_parallel)
set(RBC_FOMPAR_SCENE -options_file runs/ring_on_block.opts -contact 0 -dirichlet ring_top,block_bottom,slave -dirichlet_slave_u 0,0 -dirichlet_ring_top_u 0.01,-0.05)
rbc_add_mpi_test(NAME fom_parallel_metis RANKS 1 2 COMMAND $<TARGET_FILE:test_fom_parallel> ${RBC_FOMPAR_SCENE} -mesh_partitioner metis LABELS elasticity)
rbc_add_mpi_test(NAME fom_parallel_ptscotch RANKS 2 COMMAND $<TARGET_FILE:test_fom_parallel> ${RBC_FOMPAR_SCENE} -mesh_partitioner ptscotch LABELS elasticity)
rbc_add_mpi_test(NAME fom_parallel_p2 RANKS 2 COMMAND $<TARGET_FILE:test_fom_parallel> ${RBC_FOMPAR_SCENE} -mesh_partitioner metis -fem_degree 2 LABELS elasticity)
rbc_add_mpi_test(NAME fom_parallel_gamg RANKS 2 COMMAND $<TARGET_FILE:test_fom_parallel> ${RBC_FOMPAR_SCENE} -mesh_partitioner metis -fom_ksp_type cg -fom_pc_type gamg -fom_ksp_rtol 1e-12 -energy_rtol 1e-8 LABELS elasticity)

# Bad input. Regexes use [.] [(] [)] for literal characters (no CMake escaping needed).
set(RBC_EXPECT_ERROR bash ${CMAKE_CURRENT_SOURCE_DIR}/expect_error.sh)
set(RBC_FOM_RING $<TARGET_FILE:rbcontact_exe> fom -options_file runs/ring_on_block.opts -contact 0)
function(rbc_bad_input name regex)
  rbc_add_mpi_test(NAME bad_input_${name} RANKS 1 TIMEOUT 120 COMMAND ${RBC_EXPECT_ERROR} "${regex}" ${RBC_FOM_RING} ${ARGN} LABELS elasticity)
endfunction()
rbc_bad_input(missing_mesh "Mesh file 'meshes/no_such_mesh[.]geo' not found" -mesh_file meshes/no_such_mesh.geo)
rbc_bad_input(unknown_physical_name "Physical name 'nosuch' [(]option -dirichlet[)] does not exist in mesh 'meshes/ring_on_block[.]geo'" -dirichlet ring_top,nosuch)
rbc_bad_input(unknown_body "Physical name 'nosuchbody' [(]option -bodies[)] does not exist" -bodies ring,nosuchbody)
rbc_bad_input(E_zero "-body_E: Young's modulus 0[.]? of body 'ring' must be > 0" -body_E 0,100)
rbc_bad_input(E_negative "-body_E: Young's modulus -5[.]? of body 'block' must be > 0" -body_E 100,-5)
rbc_bad_input(nu_half "-body_nu: Poisson ratio 0[.]5 of body 'block' must lie in [(]-1, 0[.]5[)]" -body_nu 0.3,0.5)
rbc_bad_input(partitioner "Unknown value 'bogus' for option -mesh_partitioner" -mesh_partitioner bogus)
rbc_bad_input(fem_degree "-fem_degree 3 is not supported [(]1 or 2[)]" -fem_degree 3)
rbc_bad_input(garbage_msh "Mesh '[^']*garbage_mesh[.]msh' [(]from -mesh_file [^)]*garbage_mesh[.]msh[)]: [$]MeshFormat, line 2: the format version is 'this': rbcontact reads gmsh files of format 4.1" -mesh_file @GARBAGE_MSH@)
rbc_bad_input(garbage_geo "gmsh failed on '[^']*garbage_geometry[.]geo' [(]exit code [1-9][0-9]*[)]: Error.*syntax error" -mesh_file @GARBAGE_GEO@)
# The malformed mesh on 2 ranks (PETSc's reader parses on rank 0 only; the other rank used to
# hang in a collective): expect_error.sh writes the file once and launches mpiexec -n 2 itself.
add_test(NAME bad_input_garbage_msh_np2
  COMMAND ${RBC_EXPECT_ERROR} "Mesh '[^']*garbage_mesh[.]msh' [(]from -mesh_file [^)]*[)]: [$]MeshFormat, line 2: the format version is 'this'" ${RBC_MPIEXEC} -n 2 ${RBC_FOM_RING} -mesh_file @GARBAGE_MSH@
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(bad_input_garbage_msh_np2 PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 60 PROCESSORS 2 LABELS elasticity)
# An unknown name on 2 ranks: every rank's message lists the mesh's names (their union over the ranks: a rank lacking a
# label listed none before 2026-12-01)
add_test(NAME bad_input_unknown_physical_name_np2
  COMMAND ${RBC_EXPECT_ERROR} "[[]1[]] rbcontact error: Physical name 'nosuch' [(]option -dirichlet[)] does not exist in mesh 'meshes/ring_on_block[.]geo'; it has: ring, block, slave, ring_top, block_bottom, master" ${RBC_MPIEXEC} -n 2 ${RBC_FOM_RING} -dirichlet ring_top,nosuch
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(bad_input_unknown_physical_name_np2 PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 60 PROCESSORS 2 LABELS elasticity)

# The element-by-element assembly (default) against PetscFE's residual and Jacobian: A, f, H1 matrix and
# energy to 1e-12 on P1/P2, 2D/3D, mapped bodies at several mu, loads (body force, traction) and liftings.
rbc_test_exe(test_element_assembly)
rbc_add_mpi_test(NAME element_assembly_half_disks RANKS 1 2 COMMAND $<TARGET_FILE:test_element_assembly> -options_file runs/half_disks.opts -fem_degree 2 -test_mu 0.7,0.06,1.3,0.12 LABELS elasticity)
rbc_add_mpi_test(NAME element_assembly_ring_loads RANKS 1 2 COMMAND $<TARGET_FILE:test_element_assembly> -options_file runs/ring_on_block.opts -body_force 0.3,-1 -traction ring_top -traction_ring_top_t 0.5,-2 -dirichlet block_bottom,slave -dirichlet_slave_u 0.01,0.02 -test_mu 0.95,1.15 LABELS elasticity)
rbc_add_mpi_test(NAME element_assembly_block3d RANKS 1 2 COMMAND $<TARGET_FILE:test_element_assembly> -scene block3d -mesh_file meshes/block3d.geo -bodies block -body_E 100 -body_nu 0.3 -dirichlet bottom,sides -dirichlet_bottom_u 0,0,0 -dirichlet_sides_u 0.01,0,0.02 -dirichlet_sides_comps 0,2 -traction top -traction_top_t 0.1,0,-1 -body_force 0,0,-2 -contact 0 -fem_degree 2 LABELS elasticity)
# the structure check of a user's gmsh file before PETSc's reader (src/mesh/gmsh_check.hpp): a sound mesh in formats
# 4.1 (ASCII and binary) and 2.2, each fault of the fuzzing audit of 2026-12-02 (no PETSc, one process); then the FOM
# of ring_on_block from its binary 4.1 mesh on 1 and 2 ranks against the ASCII one's
rbc_test_exe(test_gmsh_check)
add_test(NAME gmsh_check COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/gmsh_check.sh $<TARGET_FILE:test_gmsh_check> ${PROJECT_SOURCE_DIR} $<TARGET_FILE:rbcontact_exe> ${RBC_MPIEXEC})
set_tests_properties(gmsh_check PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 120 PROCESSORS 2 LABELS bad_input)
