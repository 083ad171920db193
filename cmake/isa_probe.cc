// Exit 0 when the CPU this runs on implements x86-64-v3 (AVX2, FMA, BMI1/2,
// F16C, LZCNT, MOVBE): cmake/StewartIsa.cmake's probe of the build host.
int main() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("x86-64-v3") ? 0 : 1;
}
