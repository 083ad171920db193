"""The LCM log file format, read directly (no `lcm` module needed).

A log is a sequence of events, each: uint32 sync word 0xEDA1DA01, int64 event
number, int64 timestamp (us, the logger's receive time), int32 channel length,
int32 data length, the channel name, the data; all big-endian. The file is
read whole and indexed in one pass; the payloads stay where they are and are
decoded per channel later (decode.py).
"""
from dataclasses import dataclass
import struct

import numpy as np

SYNC = 0xEDA1DA01
_SYNC_BYTES = struct.pack(">I", SYNC)
_HEADER = struct.Struct(">Iqqii")
# LCM's own reader rejects longer channel names; a larger value here means the
# header is not one (a corrupt record), so the scan looks for the next sync word.
_MAX_CHANNEL_LENGTH = 1000


@dataclass
class Events:
    """Every event of a log, as parallel arrays in file order."""

    data: bytes  # the whole file: payloads are slices of it
    channels: list  # channel names; channel_id indexes this list
    channel_id: np.ndarray  # int32
    timestamp: np.ndarray  # int64, us
    offset: np.ndarray  # int64, where each payload starts in data
    length: np.ndarray  # int64, payload length in bytes
    skipped_bytes: int  # bytes of corrupt records skipped to find the next sync word
    truncated: bool  # the last event was cut short (the logger stopped mid-write)

    def payload(self, i):
        start = int(self.offset[i])
        return self.data[start:start + int(self.length[i])]


def read_events(path):
    """Indexes every event of the LCM log at `path`."""
    with open(path, "rb") as f:
        data = f.read()
    ids, stamps, offsets, lengths = [], [], [], []
    channel_ids = {}
    skipped = 0
    truncated = False
    pos, end = 0, len(data)
    unpack = _HEADER.unpack_from
    while pos + _HEADER.size <= end:
        sync, _, stamp, channel_len, data_len = unpack(data, pos)
        if sync != SYNC or not 0 < channel_len < _MAX_CHANNEL_LENGTH or data_len < 0:
            # Not a header: resynchronise on the next sync word, as LCM's reader does.
            found = data.find(_SYNC_BYTES, pos + 1)
            next_pos = found if found >= 0 else end
            skipped += next_pos - pos
            pos = next_pos
            continue
        channel_start = pos + _HEADER.size
        payload_start = channel_start + channel_len
        if payload_start + data_len > end:
            truncated = True
            break
        channel = data[channel_start:payload_start]
        channel_id = channel_ids.get(channel)
        if channel_id is None:
            channel_id = channel_ids[channel] = len(channel_ids)
        ids.append(channel_id)
        stamps.append(stamp)
        offsets.append(payload_start)
        lengths.append(data_len)
        pos = payload_start + data_len
    if 0 < end - pos < _HEADER.size:
        truncated = True
    return Events(data=data,
                  channels=[c.decode("utf-8", "replace") for c in channel_ids],
                  channel_id=np.array(ids, dtype=np.int32),
                  timestamp=np.array(stamps, dtype=np.int64),
                  offset=np.array(offsets, dtype=np.int64),
                  length=np.array(lengths, dtype=np.int64),
                  skipped_bytes=skipped,
                  truncated=truncated)
