# The build of scripts/gpu_check.sh on a GPU machine that has CUDA, CMake, a C++20 compiler and OpenMP but
# none of the Debian libraries (OpenVDB, TBB, libpng, Assimp, GoogleTest): the solver, the neighbour
# search, the scenes and the CUDA backend, and one program (tools/gpu_check.cpp) that compares the
# backends and times them. Header-only libraries come from CELLSPH_HEADERS (a folder of copies:
# nlohmann/, nanoflann.hpp) when find_package does not find them.
set(CELLSPH_HEADERS "" CACHE PATH "Folder with copies of header-only dependencies (nlohmann/, nanoflann.hpp)")
set(CELLSPH_CUDA ON CACHE STRING "" FORCE)
include(cmake/cuda.cmake)
find_package(OpenMP REQUIRED)
find_package(nlohmann_json 3 QUIET)
if(NOT nlohmann_json_FOUND)
  if(NOT EXISTS "${CELLSPH_HEADERS}/nlohmann/json.hpp")
    message(FATAL_ERROR "nlohmann-json: not installed and not in CELLSPH_HEADERS='${CELLSPH_HEADERS}'")
  endif()
  add_library(nlohmann_json::nlohmann_json INTERFACE IMPORTED)
endif()
include(cmake/builtin_scenes.cmake)

# Whole folders, subfolders included (solver/boundary/ holds the moving walls and the rigid bodies), so
# that a source added to one of them needs no edit here.
file(GLOB_RECURSE CELLSPH_GPU_SOURCES CONFIGURE_DEPENDS src/cellsph/core/*.cpp src/cellsph/neighbors/*.cpp
  src/cellsph/physics/*.cpp src/cellsph/solver/*.cpp src/cellsph/probes/*.cpp src/cellsph/scene/*.cpp
  src/cellsph/geometry/*.cpp src/cellsph/cuda/*.cu)
list(FILTER CELLSPH_GPU_SOURCES EXCLUDE REGEX "_(test|bench)\\.cpp$")
add_executable(cellsph_gpu_check tools/gpu_check.cpp ${CELLSPH_GPU_SOURCES} ${CELLSPH_SCENES_CPP})
target_include_directories(cellsph_gpu_check PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
if(CELLSPH_HEADERS)
  target_include_directories(cellsph_gpu_check SYSTEM PRIVATE ${CELLSPH_HEADERS})
endif()
# No Assimp there: the mesh reader refuses mesh files (geometry/mesh.cpp); spheres and cylinders work.
target_compile_definitions(cellsph_gpu_check PRIVATE CELLSPH_HAVE_CUDA CELLSPH_NO_ASSIMP)
target_compile_options(cellsph_gpu_check PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-O3 -Wall -Wextra>
  $<$<COMPILE_LANGUAGE:CUDA>:-O3 ${CELLSPH_CUDA_FLAGS}>)
target_link_libraries(cellsph_gpu_check PRIVATE OpenMP::OpenMP_CXX nlohmann_json::nlohmann_json CUDA::cudart_static)
# The machine's system differs from this one's: no shared C++ runtime to mismatch.
target_link_options(cellsph_gpu_check PRIVATE -static-libstdc++ -static-libgcc)
