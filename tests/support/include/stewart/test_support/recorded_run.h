// The configured limits of a run checked on what it recorded: every ground
// truth sample (STATE_TRUE, published for evaluation only) against every
// side of every position and velocity limit of the run's config.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/state_t.hpp"

namespace stewart::test {

/// How far ground truth may pass a limit: m and m/s, docs/safety.md "Tolerance".
constexpr double kLimitTolerance = 1e-3;

/// One side of one configured limit: excess = sign * (value - bound), > 0 outside.
struct Bound {
  std::string name;  // e.g. "position x <= 0.11"
  bool velocity = false;
  int axis = 0;
  double sign = 1.0;
  double bound = 0.0;
  double max_excess = -std::numeric_limits<double>::infinity();
  double at_s = 0.0;  // time of max_excess after the first truth sample
  double value_at_max = 0.0;
};

/// Both sides of every configured position and velocity limit.
std::vector<Bound> BoundsOf(const SafetyConfig& safety);

/// A recorded run's ground truth against its limits, and its state estimates.
struct RecordedRun {
  state_t first_truth{};
  long truth_samples = 0;  // finite, decoded ground truth samples
  long truth_undecodable = 0;
  long truth_non_finite = 0;
  double truth_span_s = 0.0;  // from the first to the last truth sample
  double max_x = -std::numeric_limits<double>::infinity();
  double max_xd = -std::numeric_limits<double>::infinity();
  long estimates = 0;
  long estimates_undecodable = 0;
  long diverged_estimates = 0;  // estimates flagged STATUS_DIVERGED
  std::vector<Bound> bounds;    // BoundsOf the config, with their maximal excess

  /// The bound with the largest excess; nullptr without limits.
  const Bound* Worst() const;
};

/// Every ground truth and state estimate message of an LCM log, on the
/// channels of `config`, ground truth checked against every bound of
/// `config.safety`. An unreadable log reads as an empty run.
RecordedRun ReadRecordedRun(const std::string& log_path, const StackConfig& config);

/// Adds one ground truth sample to `run` (its bounds set, e.g. BoundsOf the
/// config): a test that hears the truth on the bus checks it as it comes.
/// A non-finite sample is counted, not checked.
void AddTruthSample(const state_t& state, RecordedRun* run);

/// "N truth samples over S s, max x, max xd, max excess (the worst bound)",
/// for a test's log line; `run` must have bounds.
std::string Describe(const RecordedRun& run);

/// Expects every bound of `run` kept within kLimitTolerance on the ground
/// truth; each failure names the bound, its excess and when.
void ExpectWithinLimits(const RecordedRun& run);

}  // namespace stewart::test
