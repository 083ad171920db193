"""read_log(): an LCM log of the stack as one pandas table per channel."""
import warnings

import numpy as np
import pandas as pd

from . import columns as naming
from .decode import decode_payloads
from .lcm_types import load_types
from .logfile import read_events


def read_log(path, types_dir=None, channels=None):
    """{channel: DataFrame} of the LCM log at `path`: one row per message in
    log order, `log_utime_us` (the logger's receive time) then every field of
    the message type (column names: columns.py). `types_dir` holds the
    generated types (<build>/lcmtypes/python; default: found on sys.path, else
    this source tree's build). `channels`: only these (default: all).

    A channel is typed by its first message's fingerprint (first 8 bytes of
    the payload); its messages of another type and channels of a type the
    build does not define are left out with a warning, as stewart_log_export
    does."""
    types = load_types(types_dir)
    events = read_events(path)
    if events.skipped_bytes:
        warnings.warn(f"{path}: {events.skipped_bytes} bytes of corrupt records skipped")
    tables = {}
    for channel_id, channel in enumerate(events.channels):
        if channels is not None and channel not in channels:
            continue
        index = np.flatnonzero(events.channel_id == channel_id)
        mtype = types.get(events.payload(index[0])[:8])
        if mtype is None:
            warnings.warn(f"{channel}: {len(index)} messages of a type this build does not "
                          "define, skipped")
            continue
        index = _of_type(events, index, mtype, channel)
        tables[channel] = _table(mtype, events, index, channel)
    return tables


def _of_type(events, index, mtype, channel):
    fingerprint = mtype.generated._get_packed_fingerprint()
    same = np.array([events.data[o:o + 8] == fingerprint
                     for o in events.offset[index].tolist()], dtype=bool)
    if not same.all():
        warnings.warn(f"{channel}: {np.count_nonzero(~same)} messages not of type "
                      f"{mtype.name} (the channel's first), skipped")
    return index[same]


def _table(mtype, events, index, channel):
    """The DataFrame of the events `index`, all of type `mtype`."""
    parts = []  # (rows within the table, {(field, element): values}) per layout
    lengths = events.length[index]
    for length in np.unique(lengths):
        group = np.flatnonzero(lengths == length)
        for rows, decoded in decode_payloads(mtype, events.data, events.offset[index[group]],
                                             int(length)):
            parts.append((group[rows], decoded))
    decodable = [(rows, decoded) for rows, decoded in parts if decoded is not None]
    if len(decodable) < len(parts):
        # Left out, as stewart_log_export leaves out what does not decode.
        kept = np.sort(np.concatenate([rows for rows, _ in decodable] + [np.array([], int)]))
        warnings.warn(f"{channel}: {len(index) - len(kept)} messages that do not decode as "
                      f"{mtype.name}, skipped")
        position = np.full(len(index), -1)
        position[kept] = np.arange(len(kept))
        index = index[kept]
        decodable = [(position[rows], decoded) for rows, decoded in decodable]
    parts = decodable
    by_field = {}
    for key in sorted({key for _, decoded in parts for key in decoded}):
        by_field.setdefault(key[0], []).append(key)
    data = {"log_utime_us": events.timestamp[index]}
    for field_index, keys in by_field.items():
        field = mtype.fields[field_index]
        values = [_gather(len(index), parts, key) for key in keys]
        if naming.rule(mtype.name, field.name) == naming.HEX:
            data[field.name] = _hex(values)
            continue
        for (_, element), column in zip(keys, values):
            data[naming.column_name(mtype.name, field, element)] = column
    return pd.DataFrame(data)


def _gather(rows, parts, key):
    """One column over all rows (a field has one dtype in every layout). A
    column some rows lack (a longer variable array) holds NaN there (floats)
    or is a pandas nullable array (integers keep every bit, booleans, text)."""
    present = [(where, decoded[key]) for where, decoded in parts if key in decoded]
    if len(present) == 1 and np.array_equal(present[0][0], np.arange(rows)):
        return present[0][1]
    dtype = present[0][1].dtype
    missing = np.ones(rows, dtype=bool)
    out = np.full(rows, np.nan if dtype.kind == "f" else None if dtype.kind == "O" else 0,
                  dtype=dtype)
    for where, values in present:
        out[where] = values
        missing[where] = False
    if not missing.any() or dtype.kind in "fO":
        return out
    if dtype.kind == "b":
        return pd.arrays.BooleanArray(out, missing)
    return pd.arrays.IntegerArray(out, missing)


def _hex(elements):
    matrix = np.stack(elements, axis=1).astype(np.uint8)
    return np.array([row.tobytes().hex() for row in matrix], dtype=object)
