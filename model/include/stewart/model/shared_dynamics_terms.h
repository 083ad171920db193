#pragma once
// One evaluation of the model terms shared by components that evaluate them
// at the same state with the same parameters.
//
// In one process (the in-process closed loop, the campaign) the estimator's
// next prediction, the controller and the filter all evaluate M, C qd, G and
// H at the estimate the estimator published: one evaluation can serve the
// three. A hit returns what a new evaluation would compute, bit for bit:
// q and qd are compared exactly, and the parameters are compared field by
// field once, when a component attaches (AttachSharedTerms). Over LCM each
// process evaluates its own terms; nothing here crosses a process boundary.
#include <memory>

#include "stewart/model/dynamics.h"
#include "stewart/model/platform_params.h"

namespace stewart {

/// Whether two parameter sets are equal in every field (exact ==), i.e.
/// give the same model terms.
bool SameParams(const PlatformParams& a, const PlatformParams& b);

class SharedDynamicsTerms {
 public:
  explicit SharedDynamicsTerms(const PlatformParams& params) : params_(params) {}

  /// The terms at (q, qd) into *terms: a copy of the last evaluation's when
  /// q and qd equal its state exactly, else a new evaluation (kept).
  void Evaluate(const Vector6d& q, const Vector6d& qd, DynamicsTerms* terms);

  const PlatformParams& params() const { return params_; }
  long evaluations() const { return evaluations_; }
  long hits() const { return hits_; }

 private:
  PlatformParams params_;
  DynamicsTerms terms_;
  Vector6d q_ = Vector6d::Zero();
  Vector6d qd_ = Vector6d::Zero();
  bool valid_ = false;
  long evaluations_ = 0;
  long hits_ = 0;
};

/// The shared terms a component with `own` parameters may use: `shared`
/// itself, after checking its parameters equal `own` (std::invalid_argument
/// otherwise: sharing terms of another model would be silently wrong).
/// A null `shared` detaches (each evaluation the component's own).
std::shared_ptr<SharedDynamicsTerms> AttachSharedTerms(const PlatformParams& own,
                                                       std::shared_ptr<SharedDynamicsTerms> shared);

/// EvaluateDynamics(params, q, qd, terms), through `shared` when a
/// component has attached one (whose parameters are then `params`).
inline void EvaluateDynamics(const PlatformParams& params, SharedDynamicsTerms* shared,
                             const Vector6d& q, const Vector6d& qd, DynamicsTerms* terms) {
  if (shared != nullptr) {
    shared->Evaluate(q, qd, terms);
  } else {
    EvaluateDynamics(params, q, qd, terms);
  }
}

}  // namespace stewart
