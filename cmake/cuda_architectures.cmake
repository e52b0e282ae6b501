# The GPU architectures the CUDA backend is compiled for, from what the found nvcc supports
# (docs/platforms.md): Jetson Xavier (72) up to CUDA 12, which CUDA 13 no longer compiles for; Turing and
# Ampere (75, 80); Jetson Orin (87) from CUDA 11.4; Hopper (90) from CUDA 11.8. Machine code for each,
# and PTX for the newest, which a later GPU compiles when it loads the library. A CMAKE_CUDA_ARCHITECTURES
# given on the command line is kept. Sets ELO_NVCC_VERSION; included before enable_language(CUDA).
execute_process(COMMAND ${CMAKE_CUDA_COMPILER} --version OUTPUT_VARIABLE elo_nvcc_banner ERROR_QUIET)
string(REGEX MATCH "release ([0-9]+\\.[0-9]+)" elo_nvcc_release "${elo_nvcc_banner}")
set(ELO_NVCC_VERSION "${CMAKE_MATCH_1}")

if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
  set(elo_architectures 75 80)
  if(ELO_NVCC_VERSION VERSION_LESS 13.0)
    list(PREPEND elo_architectures 72)
  endif()
  if(NOT ELO_NVCC_VERSION VERSION_LESS 11.4)
    list(APPEND elo_architectures 87)
  endif()
  if(NOT ELO_NVCC_VERSION VERSION_LESS 11.8)
    list(APPEND elo_architectures 90)
  endif()
  list(POP_BACK elo_architectures elo_newest)
  list(TRANSFORM elo_architectures APPEND "-real")
  set(CMAKE_CUDA_ARCHITECTURES ${elo_architectures} ${elo_newest})
endif()
