# tests/usability.cmake -- what a PETSc user meets driving rbcontact from outside: provenance in every
# report and HDF5 file, the report of a failed run, -help, the boundary options renamed out of PETSc's
# -bc_ namespace, the temporary files a killed job left, the README's iterative solver on a contact scene (tests/usability_checks.py), the
# installation (tests/install_check.sh), the "your own scene" tutorial with the installed package
# (tests/tutorial_check.sh, docs/tutorial.md), Makefile.petsc (tests/makefile_petsc_check.sh).
find_program(RBC_PYTHON3_U NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
set(RBC_UC ${RBC_PYTHON3_U} ${CMAKE_CURRENT_SOURCE_DIR}/usability_checks.py)
foreach(np 1 2)
  foreach(what provenance failure rename paraview stale)
    add_test(NAME usability_${what}_np${np} COMMAND ${RBC_UC} ${what} --exe $<TARGET_FILE:rbcontact_exe> --np ${np} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(usability_${what}_np${np} PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 300 PROCESSORS ${np} LABELS usability)
  endforeach()
endforeach()
add_test(NAME usability_help COMMAND ${RBC_UC} help --exe $<TARGET_FILE:rbcontact_exe> WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
add_test(NAME usability_gamg_np2 COMMAND ${RBC_UC} gamg --exe $<TARGET_FILE:rbcontact_exe> --np 2 WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
add_test(NAME usability_rank_files_np2 COMMAND ${RBC_UC} rank_files --exe $<TARGET_FILE:rbcontact_exe> --np 2 WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(usability_help usability_gamg_np2 usability_rank_files_np2 PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 300 LABELS usability)
set_tests_properties(usability_gamg_np2 usability_rank_files_np2 PROPERTIES PROCESSORS 2)
# cmake --install into a fresh prefix; the installed binary and two outside programs (find_package, pkg-config)
add_test(NAME usability_install COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/install_check.sh ${CMAKE_BINARY_DIR})
set_tests_properties(usability_install PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 600 LABELS usability)
# docs/tutorial.md as written: cmake --install into a fresh prefix, its .geo/.opts blocks and commands from an
# empty directory with the installed binary (1 rank, about 15 s)
add_test(NAME usability_tutorial COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/tutorial_check.sh ${CMAKE_BINARY_DIR})
set_tests_properties(usability_tutorial PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 300 LABELS usability)
# Makefile.petsc (the build for users with their own PETSc/SLEPc): its info, three objects, its errors (about 8 s)
add_test(NAME usability_makefile_petsc COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/makefile_petsc_check.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(usability_makefile_petsc PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 300 LABELS usability)
