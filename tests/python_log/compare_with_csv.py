"""stewart_log's tables against stewart_log_export's CSV files of the same log.

    compare_with_csv.py LOG CSV_DIR [--types DIR] [--require CHANNEL]...

For every <channel>.csv in CSV_DIR: the channel's table has as many rows, and
each CSV column equals the table's column of that name. Values compare
exactly: the exporter prints doubles with 17 significant digits, which read
back to the same double (NaN equals NaN; the sign of zero counts). What the
CSV shapes differently is rebuilt from the table first: text as the exporter
quotes it, health's "counters" ("name=value;..."), barrier columns the CSV pads
with 0 beyond a message's count, the <channel>.barriers.csv name table.
--require: these channels must be compared (no silent pass on a short log).
Exit 0: all equal; 1: differences (listed); 2: bad input.
"""
import argparse
import os
import re
import sys

import numpy as np
import pandas as pd

import stewart_log

# Barrier columns the exporter writes up to a fixed count, 0 past the message's own.
_PADDED = re.compile(r"^(h|w|mu)_(position|velocity)\d+_$")
_COUNTERS = {"counters": "counter_values", "counter_deltas": "counter_deltas"}


def quotable(text):
    # As csv_writers.cc's Quotable(): no quote, no line break inside a quoted field.
    return text.replace('"', "'").replace("\n", "'")


def counters_text(table, values_field):
    """Health's counters as the exporter writes them: name=value;..."""
    texts = [";".join(f"{row[f'counter_names_{k}']}={row[f'{values_field}_{k}']}"
                      for k in range(int(row["num_counters"])))
             for row in table.to_dict("records")]
    return np.array(texts, dtype=object)


def expected_column(table, column, rows):
    """The table's values of a CSV column, as the CSV must hold them; None if
    the table has no such column."""
    if column in _COUNTERS and "num_counters" in table:
        return counters_text(table, _COUNTERS[column])
    if column not in table:
        return np.zeros(rows) if _PADDED.match(column) else None
    values = table[column]
    if _PADDED.match(column):
        return values.fillna(0.0).to_numpy(dtype=float)
    if values.dtype == object:
        return np.array([quotable(v) for v in values], dtype=object)
    return values.to_numpy()


def differences(expected, text):
    """Rows where the CSV's text differs from the expected values."""
    if expected.dtype == object:
        return np.flatnonzero(expected != text)
    if expected.dtype == bool:
        expected = expected.astype(np.int64)
    if expected.dtype.kind in "iu":
        return np.flatnonzero(expected != text.astype(np.int64))
    parsed = text.astype(float)
    same = (expected == parsed) & (np.signbit(expected) == np.signbit(parsed))
    same |= np.isnan(expected) & np.isnan(parsed)
    return np.flatnonzero(~same)


def compare_channel(channel, table, csv_dir, problems):
    csv = pd.read_csv(os.path.join(csv_dir, channel + ".csv"), dtype=str,
                      keep_default_na=False)
    if len(csv) != len(table):
        problems.append(f"{channel}: {len(csv)} CSV rows, {len(table)} table rows")
        return 0
    for column in csv.columns:
        expected = expected_column(table, column, len(csv))
        if expected is None:
            problems.append(f"{channel}: CSV column {column} is not in the table")
            continue
        text = csv[column].to_numpy(dtype=object if expected.dtype == object else str)
        bad = differences(expected, text)
        if bad.size:
            i = bad[0]
            problems.append(f"{channel}.{column}: {bad.size} rows differ, first row {i}: "
                            f"CSV {text[i]!r}, table {expected[i]!r}")
    sidecar = os.path.join(csv_dir, channel + ".barriers.csv")
    if os.path.exists(sidecar):
        names = pd.read_csv(sidecar, dtype=str, keep_default_na=False)
        for group, index, name in names.itertuples(index=False):
            got = table[f"{group}_names_{index}"].iloc[0]
            if got != name:
                problems.append(f"{channel}: barrier {group} {index} is {name!r} in "
                                f"{sidecar}, {got!r} in the table")
    return len(csv.columns)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("log")
    parser.add_argument("csv_dir")
    parser.add_argument("--types")
    parser.add_argument("--require", action="append", default=[])
    args = parser.parse_args()
    if not os.path.isdir(args.csv_dir):
        print(f"no folder {args.csv_dir}")
        return 2
    tables = stewart_log.read_log(args.log, args.types)
    exported = sorted(f[:-4] for f in os.listdir(args.csv_dir)
                      if f.endswith(".csv") and not f.endswith(".barriers.csv"))
    problems = []
    for channel in args.require:
        if channel not in exported or channel not in tables:
            problems.append(f"{channel}: required, but not in both the CSVs and the tables")
    for channel in exported:
        if channel not in tables:
            problems.append(f"{channel}: exported, but no table")
            continue
        table = tables[channel]
        compared = compare_channel(channel, table, args.csv_dir, problems)
        print(f"{channel}: {len(table)} rows, {compared} CSV columns compared "
              f"({len(table.columns)} table columns)")
    for channel in sorted(set(tables) - set(exported)):
        print(f"{channel}: table only ({len(tables[channel])} rows; the exporter skips its type)")
    for problem in problems:
        print("MISMATCH", problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
