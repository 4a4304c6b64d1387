# rubble_module(NAME [DEPS public...] [PRIVATE_DEPS private...] [SYSTEM_INCLUDES dirs...]):
# a static library built from every .cpp in the current folder. Each module is its own target so that it
# can be built and tested alone; every module registers itself and its dependencies in the global properties
# RUBBLE_CORE_MODULES and RUBBLE_CORE_LINK_DEPS, from which src/CMakeLists.txt makes the in-tree union
# `rubble` and the installed shared library (Rubble::rubble). DEPS are what the module's public headers need,
# PRIVATE_DEPS what only its .cpp files need. A module with no sources yet is an interface target.
function(rubble_module name)
    cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS;SYSTEM_INCLUDES" ${ARGN})
    file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
    set_property(GLOBAL APPEND PROPERTY RUBBLE_CORE_MODULES ${name})
    set_property(GLOBAL APPEND PROPERTY RUBBLE_CORE_LINK_DEPS ${ARG_DEPS} ${ARG_PRIVATE_DEPS})
    if(NOT sources)
        add_library(${name} INTERFACE)
        target_include_directories(${name} INTERFACE $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>)
        target_link_libraries(${name} INTERFACE ${ARG_DEPS})
        return()
    endif()
    add_library(${name} STATIC ${sources})
    target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
        PRIVATE ${PROJECT_SOURCE_DIR}/src)
    if(ARG_SYSTEM_INCLUDES)
        target_include_directories(${name} SYSTEM PRIVATE ${ARG_SYSTEM_INCLUDES})
    endif()
    target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS} rubble_warnings)
    target_compile_features(${name} PUBLIC cxx_std_20)
    # PIC: the same objects make the shared library. Hidden visibility: librubble.so exports what RUBBLE_API marks.
    set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON CXX_VISIBILITY_PRESET hidden
        VISIBILITY_INLINES_HIDDEN ON)
endfunction()

# rubble_shared_library(TARGET OUTPUT_NAME file EXPORT_NAME name OBJECTS static... [PUBLIC deps...]
#                       [PRIVATE deps...]): an installed shared library made of the objects of the given static
# libraries (compiled once, for both). PUBLIC are what its consumers link too, PRIVATE what only it links.
# Exported as Rubble::<name>.
function(rubble_shared_library target)
    cmake_parse_arguments(ARG "" "EXPORT_NAME;OUTPUT_NAME" "OBJECTS;PUBLIC;PRIVATE" ${ARGN})
    add_library(${target} SHARED)
    foreach(lib ${ARG_OBJECTS})
        get_target_property(type ${lib} TYPE)
        if(type STREQUAL "STATIC_LIBRARY")
            target_sources(${target} PRIVATE $<TARGET_OBJECTS:${lib}>)
        endif()
    endforeach()
    target_link_libraries(${target} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
    target_compile_features(${target} PUBLIC cxx_std_20)
    set_target_properties(${target} PROPERTIES OUTPUT_NAME ${ARG_OUTPUT_NAME} EXPORT_NAME ${ARG_EXPORT_NAME}
        VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
        LINKER_LANGUAGE CXX)
endfunction()

# rubble_test_code_uninstrumented(TARGET): under ASan, test code compiles without sanitizers (robustness.md, 7).
function(rubble_test_code_uninstrumented target)
    if(RUBBLE_SANITIZE MATCHES "address")
        target_compile_options(${target} PRIVATE -fno-sanitize=all)
    endif()
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
        # Test code at -O1: the library under test keeps its build type's flags (docs/robustness.md, section 7).
        target_compile_options(${exe} PRIVATE $<$<NOT:$<CONFIG:Debug>>:-O1>)
        rubble_test_code_uninstrumented(${exe})
        gtest_discover_tests(${exe} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} DISCOVERY_TIMEOUT 60
            PROPERTIES LABELS ${folder})
    endforeach()
endfunction()
