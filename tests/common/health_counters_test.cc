#include "stewart/common/health_counters.h"

#include <gtest/gtest.h>

namespace stewart {
namespace {

using health_state::kDegraded;
using health_state::kFault;
using health_state::kOk;
using health_state::kStarting;
using health_state::kStopped;

TEST(HealthCounters, WorstStateSinceTheLastReport) {
  HealthCounters h("test");
  EXPECT_EQ(h.TakeWorstState(), kStarting);
  h.SetState(kOk);
  h.SetState(kDegraded);  // one tick between two heartbeats
  h.SetState(kOk);
  EXPECT_EQ(h.state(), kOk);
  EXPECT_EQ(h.TakeWorstState(), kDegraded);
  EXPECT_EQ(h.TakeWorstState(), kOk);  // the next period starts at the current state
  h.SetState(kFault);
  h.SetState(kDegraded);
  h.SetState(kOk);
  EXPECT_EQ(h.TakeWorstState(), kFault);
}

TEST(HealthCounters, LifeCycleStatesAreNotWorseThanAProblem) {
  HealthCounters h("test");
  h.SetState(kOk);
  h.TakeWorstState();
  h.SetState(kDegraded);
  h.SetState(kStopped);
  EXPECT_EQ(h.TakeWorstState(), kDegraded);
  EXPECT_EQ(h.TakeWorstState(), kStopped);
}

TEST(HealthCounters, AFaultLatchesUntilAcknowledged) {
  HealthCounters h("test");
  h.SetState(kOk);
  EXPECT_FALSE(h.fault_latched());
  EXPECT_FALSE(h.AcknowledgeFault());  // nothing to acknowledge
  h.SetError("every state rejected");
  h.SetState(kFault);
  h.SetState(kOk);
  EXPECT_TRUE(h.fault_latched());
  EXPECT_EQ(h.latched_error(), "every state rejected");
  h.Reject("nan");  // later errors do not rename the latched fault
  EXPECT_EQ(h.latched_error(), "every state rejected");
  EXPECT_TRUE(h.AcknowledgeFault());
  EXPECT_FALSE(h.fault_latched());
  EXPECT_EQ(h.latched_error(), "");
}

TEST(HealthCounters, AFaultThatPersistsCannotBeAcknowledged) {
  HealthCounters h("test");
  h.SetState(kFault);
  h.SetError("link lost");  // named after entering it
  EXPECT_EQ(h.latched_error(), "link lost");
  EXPECT_FALSE(h.AcknowledgeFault());
  EXPECT_TRUE(h.fault_latched());
  h.SetState(kOk);
  h.SetError("something else");  // the fault is over: its name stays
  EXPECT_EQ(h.latched_error(), "link lost");
  EXPECT_TRUE(h.AcknowledgeFault());
}

TEST(HealthCounters, RejectionsCountInTotalAndByReason) {
  HealthCounters h("test");
  h.Reject("state_time_implausible", "utime 8e18");
  h.Reject("state_time_implausible");
  EXPECT_EQ(h.rejected_inputs(), 2);
  EXPECT_EQ(h.counter("rejected_state_time_implausible"), 2);
}

}  // namespace
}  // namespace stewart
