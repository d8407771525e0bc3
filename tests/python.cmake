# tests/python.cmake -- the Python module (python/module.cpp, tests/python_checks.py): a ROM of ring_on_block
# driven from Python (100 radii, the same forces as `rbcontact online`, the FOM's to 1e-3, bad input raising).
# Registered when the module is built (pybind11 found, CMakeLists.txt).
if(TARGET rbcontact_python)
  find_program(RBC_PYTHON3_PY NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
  add_test(NAME python_module COMMAND ${RBC_PYTHON3_PY} ${CMAKE_CURRENT_SOURCE_DIR}/python_checks.py --exe $<TARGET_FILE:rbcontact_exe> --pythonpath ${RBC_PYTHON_BUILD_DIR}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(python_module PROPERTIES ENVIRONMENT "${RBC_MPI_ENV}" TIMEOUT 300 PROCESSORS 2 LABELS "python;rom")
endif()
