// The tree is compiled for the instruction-set level cmake chose
// (cmake/StewartIsa.cmake, docs/performance.md "Instruction set"), and the
// CPU running the tests implements it (a build for x86-64-v3 copied to an
// older CPU would stop with SIGILL before here; this names the mismatch
// when the probe and the flags disagree).
#include <gtest/gtest.h>

#include <string>

namespace {

TEST(InstructionSet, TheCodeIsCompiledForTheLevelCmakeChose) {
  const std::string level = STEWART_ISA_IN_USE;
#if defined(__AVX2__) && defined(__FMA__)
  const bool compiled_v3 = true;
#else
  const bool compiled_v3 = false;
#endif
  EXPECT_EQ(compiled_v3, level == "x86-64-v3") << "STEWART_ISA_IN_USE " << level;
  if (level == "x86-64-v3") {
    __builtin_cpu_init();
    EXPECT_TRUE(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        << "built for x86-64-v3 on a CPU without AVX2 or FMA";
  }
}

}  // namespace
