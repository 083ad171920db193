#pragma once
// Kernel-side channel filtering for LCM's udpm wire format (Linux).
//
// Every LCM socket on a udpm URL joins one multicast group, so the kernel
// hands every datagram of the bus to every process. A classic BPF socket
// filter drops, in the kernel, the messages of channels a process does not
// subscribe to: it is not woken for them (docs/operations.md, "How the nodes
// receive").
//
// What passes: every short message ("LC02") and every first fragment of a
// fragmented one ("LC03", fragment 0, the only one naming its channel) whose
// channel is exactly one of `channels`; the later fragments of any message
// (the receiver keeps them only for a message whose first fragment it kept);
// anything that is not LCM (the receiver counts it as bad).
#include <linux/filter.h>

#include <string>
#include <vector>

namespace stewart {

/// The socket-filter program, for a UDP socket (the program sees the
/// datagram from the UDP header on). Channels are compared including the
/// name's terminating NUL, so "A" does not pass "AB". Empty when a name is
/// too long for the program's 8-bit jumps (the names' comparisons together
/// longer than 255 instructions, about 400 characters in all).
std::vector<sock_filter> BuildLcmChannelFilter(std::vector<std::string> channels);

}  // namespace stewart
