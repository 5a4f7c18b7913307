# quadcosim's runs with FMUs in them: an FMU as the plant (fmu_plant, behind sim::ExternalDynamics)
# and as the controller (fmu_controller, a control::Controller), mapped by fmu_mapping. Included
# from CMakeLists.txt beside it.
add_library(quadcosim_fmi_master STATIC fmu_mapping.cpp fmu_plant.cpp fmu_controller.cpp)
target_include_directories(quadcosim_fmi_master PUBLIC ${PROJECT_SOURCE_DIR}/src)
target_link_libraries(quadcosim_fmi_master PUBLIC quadcosim_fmi quadcosim_sim quadcosim_control quadcosim_model
                      fmt::fmt)

if(QUADCOSIM_BUILD_TESTS)
  # Over an in-memory FMU, and the point mass of tests/fmi loaded from its .fmu.
  quadcosim_add_gtest(fmi_master_test SOURCES fmu_master_test.cpp LIBS quadcosim_fmi_master)
  add_dependencies(fmi_master_test fmi_test_fmus)
  target_compile_definitions(fmi_master_test PRIVATE QUADCOSIM_TEST_FMU_DIR="${CMAKE_BINARY_DIR}/tests/fmi")
endif()
