#pragma once
// Kernel-side channel filtering for LCM's udpm wire format (Linux).
//
// Every LCM socket on a udpm URL joins one multicast group, so the kernel
// hands every datagram of the bus to every process. A classic BPF socket
// filter drops, in the kernel, the short messages of channels a process does
// not subscribe to: it is not woken for them (docs/operations.md, "How the
// nodes receive").
//
// What passes: every datagram that is not a short LCM message ("LC02"),
// i.e. fragments of large messages ("LC03") and anything else, and every
// short message whose channel is exactly one of `channels`.
#include <linux/filter.h>

#include <string>
#include <vector>

namespace stewart {

/// The socket-filter program, for a UDP socket (the program sees the
/// datagram from the UDP header on). Channels are compared including the
/// name's terminating NUL, so "A" does not pass "AB". Empty when a name is
/// too long for the program's 8-bit jumps (> ~500 characters).
std::vector<sock_filter> BuildLcmChannelFilter(std::vector<std::string> channels);

}  // namespace stewart
