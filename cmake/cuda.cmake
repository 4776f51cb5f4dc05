# The CUDA backend (src/cellsph/cuda/*.cu): optional, the CPU build stands alone. CMake 3.25 does not know
# CUDA C++20 (docs/gpu.md): its flag is given by hand. Architectures explicit: `native` fails without a GPU.
set(CELLSPH_HAVE_CUDA OFF)
if(NOT CELLSPH_CUDA STREQUAL "OFF")
  include(CheckLanguage)
  if(NOT CMAKE_CUDA_COMPILER AND NOT DEFINED ENV{CUDACXX} AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc)
  endif()
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    set(CELLSPH_HAVE_CUDA ON)
  elseif(CELLSPH_CUDA STREQUAL "ON")
    message(FATAL_ERROR "CELLSPH_CUDA=ON but no CUDA compiler (nvcc) was found: set CMAKE_CUDA_COMPILER, or CELLSPH_CUDA=OFF")
  endif()
endif()
if(CELLSPH_HAVE_CUDA)
  if(NOT CMAKE_CUDA_ARCHITECTURES)
    # Where a GPU is seen, its own architecture (`native` fails without one). Elsewhere (CI, a login node)
    # only PTX for sm_80, which the driver compiles once for any GPU from the A100 on: half the compile
    # time of machine code for two architectures. A build for another machine names its architectures.
    execute_process(COMMAND nvidia-smi -L RESULT_VARIABLE gpu_rc OUTPUT_VARIABLE gpu_list ERROR_QUIET)
    if(gpu_rc EQUAL 0 AND gpu_list MATCHES "GPU [0-9]")
      set(CMAKE_CUDA_ARCHITECTURES native)
    else()
      set(CMAKE_CUDA_ARCHITECTURES 80-virtual)
    endif()
  endif()
  if(NOT CMAKE_CUDA_HOST_COMPILER)
    set(CMAKE_CUDA_HOST_COMPILER ${CMAKE_CXX_COMPILER})
  endif()
  enable_language(CUDA)
  set(CMAKE_CUDA20_STANDARD_COMPILE_OPTION -std=c++20)
  set(CMAKE_CUDA20_EXTENSION_COMPILE_OPTION -std=c++20)
  set(CMAKE_CUDA_STANDARD 20)
  set(CMAKE_CUDA_STANDARD_REQUIRED ON)
  set(CMAKE_CUDA_EXTENSIONS OFF)
  find_package(CUDAToolkit REQUIRED)
  # The passes are __host__ __device__ functions that call constexpr std:: helpers (std::max); the CPU
  # driver's OpenMP pragmas reach the host side of the .cu files. --fmad=false: no contraction of a * b + c
  # into one rounding, as on the CPU (g++ with -std=c++20 does not contract), so the device computes the
  # CPU's expressions with the CPU's roundings (division and sqrt are IEEE-rounded by default): the
  # neighbour tests (distance2 <= h^2) give the same pairs, and the step the same values where the
  # libraries' functions agree (docs/gpu.md).
  set(CELLSPH_CUDA_FLAGS --expt-relaxed-constexpr -Xcompiler=-fopenmp --fmad=false)
  message(STATUS "cellsph: CUDA backend ON (nvcc ${CMAKE_CUDA_COMPILER_VERSION}, architectures ${CMAKE_CUDA_ARCHITECTURES})")
else()
  message(STATUS "cellsph: CUDA backend OFF (CELLSPH_CUDA=${CELLSPH_CUDA})")
endif()
