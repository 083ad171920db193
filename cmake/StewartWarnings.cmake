# Warnings as errors on our own code only (generated LCM headers and system
# headers are included as SYSTEM so their warnings never fail the build).
function(stewart_target_warnings target)
  # maybe-uninitialized stays a warning: GCC 12 raises it inside lcm-gen's
  # decode code once it is inlined into ours, where -isystem cannot hide it.
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
                                           -Wnon-virtual-dtor -Werror
                                           -Wno-error=maybe-uninitialized)
endfunction()

# Release builds keep assertions off but stay debuggable.
string(APPEND CMAKE_CXX_FLAGS_RELEASE " -g1")

# A program's command-line glue (its main: CLI11 flags, wiring to the
# libraries) does no numeric work, so it compiles at -O1: CLI11's
# header-only code and <regex> cost about a third less CPU there than at -O3
# (docs/performance.md, "Build time"). Sources of the current directory.
function(stewart_glue_sources)
  set_source_files_properties(${ARGN} PROPERTIES COMPILE_OPTIONS -O1)
endfunction()
