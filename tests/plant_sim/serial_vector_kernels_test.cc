// The installed vector kernels against the SUNDIALS serial ones, operation
// by operation, on random data, including the aliasing SUNDIALS allows.
#include "stewart/plant_sim/serial_vector_kernels.h"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <array>
#include <cmath>
#include <random>

namespace stewart {
namespace {

constexpr int kLength = 18;
constexpr int kVectors = 8;

// The same random vectors twice: `ref` with the library's kernels (fused
// operations enabled, so they exist), `ours` with the installed ones.
class SerialVectorKernels : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(SUNContext_Create(nullptr, &context_), 0);
    N_Vector ref_template = N_VNew_Serial(kLength, context_);
    N_VEnableFusedOps_Serial(ref_template, SUNTRUE);
    N_Vector our_template = N_VNew_Serial(kLength, context_);
    InstallSerialVectorKernels(our_template);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> value(-2.0, 2.0);
    for (int j = 0; j < kVectors; ++j) {
      ref_[j] = N_VClone(ref_template);  // clones carry the template's operations
      ours_[j] = N_VClone(our_template);
      for (int i = 0; i < kLength; ++i) {
        const double v = value(rng);
        NV_Ith_S(ref_[j], i) = v;
        NV_Ith_S(ours_[j], i) = v;
      }
    }
    N_VDestroy(ref_template);
    N_VDestroy(our_template);
  }
  void TearDown() override {
    for (int j = 0; j < kVectors; ++j) {
      N_VDestroy(ref_[j]);
      N_VDestroy(ours_[j]);
    }
    SUNContext_Free(&context_);
  }
  // Every vector agrees to round-off (the library special-cases some
  // coefficients, e.g. c (x + y) for a = b, so not always to the bit).
  void ExpectSame() const {
    for (int j = 0; j < kVectors; ++j) {
      for (int i = 0; i < kLength; ++i) {
        EXPECT_NEAR(NV_Ith_S(ours_[j], i), NV_Ith_S(ref_[j], i),
                    4e-16 * (1.0 + std::abs(NV_Ith_S(ref_[j], i))))
            << "vector " << j << " element " << i;
      }
    }
  }
  SUNContext context_ = nullptr;
  std::array<N_Vector, kVectors> ref_{};
  std::array<N_Vector, kVectors> ours_{};
};

TEST_F(SerialVectorKernels, InheritedByClones) {
  EXPECT_NE(ours_[0]->ops->nvlinearsum, ref_[0]->ops->nvlinearsum);
  EXPECT_NE(ours_[0]->ops->nvlinearcombination, nullptr);
}

TEST_F(SerialVectorKernels, LinearSumIncludingAliasing) {
  for (const auto& v : {&ref_, &ours_}) {
    N_VLinearSum(0.3, (*v)[0], -1.7, (*v)[1], (*v)[2]);
    N_VLinearSum(1.0, (*v)[3], 2.5, (*v)[4], (*v)[3]);   // z = x
    N_VLinearSum(-0.5, (*v)[5], 1.0, (*v)[6], (*v)[6]);  // z = y
    N_VLinearSum(0.7, (*v)[7], 0.7, (*v)[0], (*v)[1]);   // a = b
  }
  ExpectSame();
}

TEST_F(SerialVectorKernels, ElementwiseOperations) {
  for (const auto& v : {&ref_, &ours_}) {
    N_VScale(-3.0, (*v)[0], (*v)[1]);
    N_VScale(0.25, (*v)[2], (*v)[2]);
    N_VAbs((*v)[3], (*v)[4]);
    N_VInv((*v)[4], (*v)[5]);
    N_VAddConst((*v)[5], 1e-3, (*v)[6]);
    N_VProd((*v)[6], (*v)[0], (*v)[7]);
    N_VDiv((*v)[7], (*v)[4], (*v)[3]);
    N_VConst(0.125, (*v)[2]);
  }
  ExpectSame();
}

TEST_F(SerialVectorKernels, Reductions) {
  const double refs[] = {N_VDotProd(ref_[0], ref_[1]), N_VMaxNorm(ref_[2]), N_VMin(ref_[3]),
                         N_VWrmsNorm(ref_[4], ref_[5]), N_VWSqrSumLocal(ref_[6], ref_[7])};
  const double ours[] = {N_VDotProd(ours_[0], ours_[1]), N_VMaxNorm(ours_[2]), N_VMin(ours_[3]),
                         N_VWrmsNorm(ours_[4], ours_[5]), N_VWSqrSumLocal(ours_[6], ours_[7])};
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(ours[k], refs[k], 1e-15 * (1.0 + std::abs(refs[k]))) << k;
}

TEST_F(SerialVectorKernels, FusedOperations) {
  std::array<double, kVectors> c = {1.0, 0.2, -0.3, 0.45, -1.1, 2.0, 0.05, -0.6};
  for (const auto& v : {&ref_, &ours_}) {
    // An ERK stage z = y + h sum a_j F_j, in place as ARKODE does (z = X_0).
    N_VLinearCombination(5, c.data(), v->data(), (*v)[0]);
    N_VLinearCombination(3, c.data() + 4, v->data() + 1, (*v)[7]);
    N_VLinearCombination(1, c.data() + 2, v->data() + 6, (*v)[6]);
    N_Vector Y[2] = {(*v)[2], (*v)[3]};
    N_Vector Z[2] = {(*v)[4], (*v)[3]};
    N_VScaleAddMulti(2, c.data() + 1, (*v)[5], Y, Z);
    N_VConstVectorArray(1, -4.0, v->data() + 5);
  }
  ExpectSame();
}

TEST_F(SerialVectorKernels, VectorArrays) {
  std::array<double, kVectors> c = {0.5, -2.0, 3.0, 1.0, 0.0, 1.5, -0.25, 0.75};
  double ref_norms[2], our_norms[2];
  N_VWrmsNormVectorArray(2, ref_.data(), ref_.data() + 2, ref_norms);
  N_VWrmsNormVectorArray(2, ours_.data(), ours_.data() + 2, our_norms);
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(our_norms[k], ref_norms[k], 1e-15 * ref_norms[k]);
  for (const auto& v : {&ref_, &ours_}) {
    N_VLinearSumVectorArray(2, 0.3, v->data(), -0.9, v->data() + 2, v->data() + 4);
    N_VScaleVectorArray(2, c.data(), v->data() + 4, v->data() + 6);
  }
  ExpectSame();
}

TEST(SerialVectorKernelsInstall, RejectsOtherVectors) {
  EXPECT_THROW(InstallSerialVectorKernels(nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace stewart
