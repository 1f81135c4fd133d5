# Settings shared by the tests, benchmarks and examples (never by the library target).
set(CMAKE_CXX_STANDARD 20)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)
if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
  set(CMAKE_BUILD_TYPE Release CACHE STRING "Build type" FORCE)
endif()

find_package(embree 3 REQUIRED)
find_package(OpenMP REQUIRED)
find_package(assimp REQUIRED)
find_package(Threads REQUIRED)

# Where cmake/install-deps.sh unpacked CGAL's meshes.
if(DEFINED ENV{XDG_CACHE_HOME})
  set(_infolerp_cache "$ENV{XDG_CACHE_HOME}")
else()
  set(_infolerp_cache "$ENV{HOME}/.cache")
endif()
set(INFOLERP_DATA_DIR "${_infolerp_cache}/infolerp/meshes" CACHE PATH "CGAL mesh data (see cmake/install-deps.sh)")

# Warnings are errors on g++ and clang++ for every target we build.
function(infolerp_strict target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wconversion -Wshadow -Werror)
endfunction()

# tests/support: the Embree tracer, scenes, mesh loading, images; shared by tests,
# benchmarks and examples, so it is compiled once.
file(GLOB _infolerp_support_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tests/support/*.cpp)
add_library(infolerp_support STATIC ${_infolerp_support_sources})
target_include_directories(infolerp_support PUBLIC ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(infolerp_support PUBLIC infolerp::infolerp embree OpenMP::OpenMP_CXX Threads::Threads
                      PRIVATE assimp::assimp)
target_compile_definitions(infolerp_support PUBLIC INFOLERP_DATA_DIR="${INFOLERP_DATA_DIR}")
infolerp_strict(infolerp_support)
