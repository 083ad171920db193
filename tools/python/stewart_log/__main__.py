"""python3 -m stewart_log FILE: the channels of an LCM log, their message
types and counts, and the log's duration; --decode also reads every channel
into its table (read_log) and says how long that took.

The duration is the span of the logger's receive times (wall clock); per
channel, the span and rate are in stack time (the messages' utime), which in
lockstep runs faster than the wall clock."""
import argparse
import sys
import time

import numpy as np

from .lcm_types import load_types
from .logfile import read_events
from .reader import read_log


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m stewart_log", description=__doc__)
    parser.add_argument("log", help="LCM log file")
    parser.add_argument("--types", help="the generated types (<build>/lcmtypes/python)")
    parser.add_argument("--decode", action="store_true",
                        help="also decode every channel and time it")
    args = parser.parse_args(argv)

    types = load_types(args.types)
    events = read_events(args.log)
    if len(events.timestamp) == 0:
        print(f"{args.log}: no events")
        return 1
    duration_s = (events.timestamp.max() - events.timestamp.min()) * 1e-6
    print(f"{args.log}: {len(events.timestamp)} messages on {len(events.channels)} channels "
          f"over {duration_s:.3f} s (logger receive times)")
    if events.skipped_bytes:
        print(f"  {events.skipped_bytes} bytes of corrupt records skipped")
    if events.truncated:
        print("  the last event is cut short (not counted)")
    print(f"  {'channel':<28} {'type':<30} {'messages':>9} {'stack_s':>9} {'rate_hz':>9}")
    for channel_id, channel in sorted(enumerate(events.channels), key=lambda c: c[1]):
        index = np.flatnonzero(events.channel_id == channel_id)
        mtype = types.get(events.payload(index[0])[:8])
        span_s = _stack_time_span_s(events, index, mtype)
        span = f"{span_s:.3f}" if span_s is not None else "-"
        rate = f"{(len(index) - 1) / span_s:.1f}" if span_s else "-"
        type_name = mtype.name if mtype else "(unknown type)"
        print(f"  {channel:<28} {type_name:<30} {len(index):>9} {span:>9} {rate:>9}")
    if args.decode:
        start = time.perf_counter()
        tables = read_log(args.log, args.types)
        elapsed = time.perf_counter() - start
        cells = sum(t.size for t in tables.values())
        print(f"read_log: {len(tables)} tables, {cells} values in {elapsed:.2f} s")
    return 0


def _stack_time_span_s(events, index, mtype):
    """Last minus first utime of the channel's messages; None when its type
    does not start with an int64 utime (every stewart type does)."""
    if mtype is None or mtype.fields[0].name != "utime" or mtype.fields[0].type != "int64_t":
        return None
    fingerprint = mtype.generated._get_packed_fingerprint()
    stamps = [events.data[o + 8:o + 16] for o, n in zip(events.offset[index].tolist(),
                                                       events.length[index].tolist())
              if n >= 16 and events.data[o:o + 8] == fingerprint]
    utime = np.frombuffer(b"".join(stamps), dtype=">i8")
    return (utime.max() - utime.min()) * 1e-6 if len(utime) else None


if __name__ == "__main__":
    sys.exit(main())
