#pragma once
// The bridge's link session (docs/wire-protocol.md, "Sessions"): a number
// drawn at random when a bridge starts, carried in every command frame, so
// the device can tell a restarted bridge from the late frames of the one
// before it.
#include <cstdint>

namespace stewart::hw {

/// A random session, never 0 (0 means "none" on the wire). From the
/// operating system's entropy: two starts within the same microsecond, or
/// of two hosts, still differ.
uint32_t NewLinkSession();

}  // namespace stewart::hw
