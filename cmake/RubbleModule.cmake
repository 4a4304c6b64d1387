# rubble_module(NAME [DEPS public...] [PRIVATE_DEPS private...] [SYSTEM_INCLUDES dirs...]):
# a static library built from every .cpp in the current folder. Each module is its own target so that it
# can be built and tested alone. A module with no sources yet is an interface target.
function(rubble_module name)
    cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS;SYSTEM_INCLUDES" ${ARGN})
    file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
    if(NOT sources)
        add_library(${name} INTERFACE)
        target_include_directories(${name} INTERFACE ${PROJECT_SOURCE_DIR}/include)
        target_link_libraries(${name} INTERFACE ${ARG_DEPS})
        return()
    endif()
    add_library(${name} STATIC ${sources})
    target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR}/include PRIVATE ${PROJECT_SOURCE_DIR}/src)
    if(ARG_SYSTEM_INCLUDES)
        target_include_directories(${name} SYSTEM PRIVATE ${ARG_SYSTEM_INCLUDES})
    endif()
    target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS} rubble_warnings)
    set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

# rubble_tests(FOLDER LIBS...): one GoogleTest executable per *_test.cpp in FOLDER, registered with CTest.
function(rubble_tests folder)
    file(GLOB tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${folder}/*_test.cpp)
    foreach(src ${tests})
        get_filename_component(stem ${src} NAME_WE)
        set(exe ${folder}_${stem})
        add_executable(${exe} ${src})
        target_link_libraries(${exe} PRIVATE ${ARGN} rubble_test_support GTest::gtest_main rubble_warnings)
        set_target_properties(${exe} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
        gtest_discover_tests(${exe} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} DISCOVERY_TIMEOUT 60
            PROPERTIES LABELS ${folder})
    endforeach()
endfunction()
