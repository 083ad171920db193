# The x86-64 level the whole tree is compiled for (docs/performance.md,
# "Instruction set"). STEWART_ISA:
#   auto       x86-64-v3 when the build host implements it, else baseline
#              (tools/setup.sh builds on the machine that runs the stack)
#   baseline   plain x86-64 (SSE2): binaries that run on any x86-64 CPU
#   x86-64-v3  AVX2 and FMA (Haswell, 2013, and Zen onwards): the EKF about
#              1.5x and the closed loop 1.2x faster; SIGILL on older CPUs
# One level for every target of the tree: Eigen's fixed-size types change
# alignment with AVX, so objects compiled for two levels must not share them.
set(STEWART_ISA "auto" CACHE STRING "x86-64 level: auto | baseline | x86-64-v3")
set_property(CACHE STEWART_ISA PROPERTY STRINGS auto baseline x86-64-v3)

if(STEWART_ISA STREQUAL "auto")
  set(_stewart_isa baseline)
  if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
    try_run(_stewart_isa_run _stewart_isa_compiled ${CMAKE_BINARY_DIR}/isa_probe
            ${CMAKE_CURRENT_LIST_DIR}/isa_probe.cc)
    if(_stewart_isa_compiled AND _stewart_isa_run EQUAL 0)
      set(_stewart_isa x86-64-v3)
    endif()
  endif()
elseif(STEWART_ISA STREQUAL "baseline" OR STEWART_ISA STREQUAL "x86-64-v3")
  set(_stewart_isa ${STEWART_ISA})
else()
  message(FATAL_ERROR "STEWART_ISA: '${STEWART_ISA}' is none of auto, baseline, x86-64-v3")
endif()

if(_stewart_isa STREQUAL "x86-64-v3")
  add_compile_options(-march=x86-64-v3)
endif()
set(STEWART_ISA_IN_USE ${_stewart_isa})
message(STATUS "stewart: instruction set ${_stewart_isa} (STEWART_ISA=${STEWART_ISA})")
