"""stewart_log (tools/python) on logs written here with lcm-gen's Python
classes: every cell of every table equals what the generated decoder gives
message by message (so the numpy layouts are checked on every row, through
layout changes within a channel); foreign, corrupt and truncated records are
skipped and reported; the CLI counts what the log holds.

Run with tools/python and <build>/lcmtypes/python on PYTHONPATH (ctest sets it).
"""
import math
import os
import random
import struct
import subprocess
import sys
import tempfile
import unittest
import warnings

import numpy as np
import pandas as pd

import stewart_log
from stewart_log import columns as naming
from stewart_log.logfile import SYNC

TYPES = {t.name: t for t in stewart_log.load_types().values()}


def generated(name):
    return TYPES[f"stewart.{name}"].generated


def write_log(path, events, tail=b""):
    """events: (channel, payload, timestamp_us); `tail` is appended raw."""
    with open(path, "wb") as f:
        for number, (channel, payload, stamp) in enumerate(events):
            name = channel.encode()
            f.write(struct.pack(">Iqqii", SYNC, number, stamp, len(name), len(payload)))
            f.write(name + payload)
        f.write(tail)


def reference_row(type_name, payload, stamp):
    """{column: value} of one payload, decoded by lcm-gen's class."""
    mtype = TYPES[type_name]
    message = mtype.generated.decode(payload)
    row = {"log_utime_us": stamp}
    for field in mtype.fields:
        value = getattr(message, field.name)
        values = list(np.ravel(np.array(value, dtype=object))) if field.dims else [value]
        if naming.rule(type_name, field.name) == naming.HEX:
            row[field.name] = bytes(v & 0xFF for v in values).hex()
            continue
        for element, v in enumerate(values):
            row[naming.column_name(type_name, field, element)] = v
    return row


def same(got, want):
    """A table cell equals the generated decoder's value; `want` None: the
    message has no such element (NaN, None or pandas' NA in the table)."""
    if want is None:
        return got is None or got is pd.NA or (isinstance(got, float) and math.isnan(got))
    if isinstance(want, float):  # bit for bit: NaN, -0.0
        return isinstance(got, float) and struct.pack(">d", got) == struct.pack(">d", want)
    return got is not pd.NA and got is not None and got == want and type(got) is type(want)


class Messages:
    """Messages of every type with varied values, encoded by the generated classes."""

    def __init__(self, seed):
        self.rng = random.Random(seed)

    def doubles(self, n):
        special = [float("nan"), float("inf"), -float("inf"), -0.0, 5e-324, 1.7976931348623157e308]
        return [self.rng.choice(special) if self.rng.random() < 0.05
                else self.rng.uniform(-1e3, 1e3) for _ in range(n)]

    def ints(self, bits):
        return self.rng.randint(-2 ** (bits - 1), 2 ** (bits - 1) - 1)

    def stamped(self, msg, k):
        msg.utime, msg.seq, msg.sample_utime = 1000 * k + self.ints(8), k, self.ints(64)
        return msg

    def state(self, k):
        m = self.stamped(generated("state_t")(), k)
        for f in ("q", "qd", "q_std", "qd_std", "disturbance", "disturbance_std"):
            setattr(m, f, self.doubles(6))
        m.status = self.ints(32)
        return m.encode()

    def sensor(self, k):
        m = self.stamped(generated("sensor_t")(), k)
        m.leg_length_m, m.gyro_radps, m.accel_mps2 = self.doubles(6), self.doubles(3), self.doubles(3)
        m.has_orientation = self.rng.random() < 0.5
        m.orientation_rpy_rad, m.status = self.doubles(3), self.ints(32)
        return m.encode()

    def command(self, k):
        m = self.stamped(generated("force_command_t")(), k)
        m.force_n, m.flags, m.session_id = self.doubles(6), self.ints(32), self.ints(64)
        m.mac = [self.ints(8) for _ in range(32)]
        return m.encode()

    def diagnostics(self, k):
        # The barrier count changes within the channel (a layout per count).
        m = self.stamped(generated("safety_diagnostics_t")(), k)
        m.variant, m.correction_metric, m.active_case = self.ints(8), self.ints(8), self.ints(8)
        m.infeasible, m.fallback_reason = self.rng.random() < 0.5, self.ints(32)
        m.num_position = (24, 20, 0)[(k // 7) % 3]
        m.position_names = [f"leg{i}_{'upper' if i % 2 else 'lower'}" for i in range(m.num_position)]
        m.num_velocity = 12
        m.velocity_names = [f"v{i}" + "é" * (k % 2) for i in range(12)]
        for group, n in (("position", m.num_position), ("velocity", 12)):
            for q in ("h", "alpha_h", "w", "mu"):
                setattr(m, f"{q}_{group}", self.doubles(n))
        m.h_pos, m.h_vel, m.psi_p, m.psi_v, m.mu_p, m.mu_v = self.doubles(6)
        m.g_p, m.g_v, m.mu_force, m.f_des, m.f_safe = (self.doubles(6) for _ in range(5))
        m.correction_norm, m.compute_ns, m.flags = self.doubles(1)[0], self.ints(64), self.ints(32)
        m.force_limits = self.rng.random() < 0.5
        return m.encode()

    def health(self, k):
        # Processes with different counters and texts share the channel.
        m = self.stamped(generated("health_t")(), k)
        m.name = ("plant_sim", "estimator", "safety")[k % 3]
        m.state, m.worst_state, m.fault_latched = self.ints(8), self.ints(8), k % 2 == 0
        m.latched_error = "" if k % 4 else 'stale "input", 12 ms\nlate'
        for f in ("messages_in", "messages_out", "rejected_inputs", "period_us",
                  "messages_in_delta", "messages_out_delta", "rejected_inputs_delta"):
            setattr(m, f, self.ints(64))
        m.num_counters = k % 3 + 1
        m.counter_names = [f"c{i}_{m.name}" for i in range(m.num_counters)]
        m.counter_values = [self.ints(64) for _ in range(m.num_counters)]
        m.counter_deltas = [self.ints(64) for _ in range(m.num_counters)]
        m.last_error = "ünïcode ✓" if k % 5 == 0 else ""
        return m.encode()

    def supervisor(self, k):
        m = self.stamped(generated("supervisor_state_t")(), k)
        m.session_id, m.state, m.arming_progress = self.ints(64), self.ints(8), self.doubles(1)[0]
        m.motion_time_us, m.transitions = self.ints(64), self.ints(64)
        m.operator_commands_accepted, m.operator_commands_rejected = self.ints(64), self.ints(64)
        m.reason, m.fault_latched = f"reason {k}", self.ints(8)
        m.last_operator_id, m.last_operator_seq = self.ints(64), self.ints(64)
        m.last_operator_reply = "" if k % 2 else "rejected: stale"
        m.mac = [self.ints(8) for _ in range(32)]
        return m.encode()

    def setpoint(self, k):
        m = self.stamped(generated("setpoint_t")(), k)
        m.q_des, m.qd_des, m.qdd_des = self.doubles(6), self.doubles(6), self.doubles(6)
        return m.encode()


CHANNELS = {
    "STATE_EST": ("stewart.state_t", Messages.state),
    "SENSORS": ("stewart.sensor_t", Messages.sensor),
    "CMD_SAFE": ("stewart.force_command_t", Messages.command),
    "SAFETY_DIAG": ("stewart.safety_diagnostics_t", Messages.diagnostics),
    "HEALTH": ("stewart.health_t", Messages.health),
    "SUPERVISOR": ("stewart.supervisor_state_t", Messages.supervisor),
    "SETPOINT": ("stewart.setpoint_t", Messages.setpoint),
}


class ReaderTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.TemporaryDirectory(prefix="stewart_log_test_")
        self.path = os.path.join(self.folder.name, "log.lcm")

    def tearDown(self):
        self.folder.cleanup()

    def make_events(self, count=60):
        messages = Messages(seed=7)
        events, expected = [], {c: [] for c in CHANNELS}
        stamp = 1_000_000
        for k in range(count):
            for channel, (type_name, make) in CHANNELS.items():
                if channel == "HEALTH" and k % 2:
                    continue
                payload = make(messages, k)
                stamp += messages.rng.randint(1, 300)
                events.append((channel, payload, stamp))
                expected[channel].append(reference_row(type_name, payload, stamp))
        return events, expected

    def assert_table(self, channel, table, rows):
        columns = list(dict.fromkeys(c for row in rows for c in row))
        self.assertEqual(sorted(table.columns), sorted(columns), channel)
        self.assertEqual(len(table), len(rows), channel)
        for i, row in enumerate(rows):
            for column in columns:
                got = table[column].iloc[i]
                got = got.item() if isinstance(got, np.generic) else got
                want = row.get(column)
                self.assertTrue(same(got, want),
                                f"{channel} row {i} {column}: table {got!r}, generated {want!r}")

    def test_every_cell_equals_the_generated_decoder(self):
        events, expected = self.make_events()
        write_log(self.path, events)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            tables = stewart_log.read_log(self.path)
        self.assertEqual(set(tables), set(CHANNELS))
        for channel, rows in expected.items():
            self.assert_table(channel, tables[channel], rows)
        # The table's own names, as stewart_log_export has them.
        self.assertIn("q_phi_rad", tables["STATE_EST"].columns)
        self.assertIn("f_safe5_n", tables["SAFETY_DIAG"].columns)
        self.assertIn("h_position23_", tables["SAFETY_DIAG"].columns)
        # A barrier a message does not have is NaN there, its name None.
        diag = tables["SAFETY_DIAG"]
        few = diag["num_position"] == 0
        self.assertTrue(diag.loc[few, "h_position0_"].isna().all())
        self.assertTrue(diag.loc[few, "position_names_0"].isna().all())
        self.assertEqual(diag["h_position0_"].dtype, np.float64)
        self.assertEqual(tables["STATE_EST"]["seq"].dtype, np.int64)
        self.assertEqual(tables["SENSORS"]["has_orientation"].dtype, bool)

    def test_foreign_corrupt_and_truncated_records_are_skipped(self):
        events, expected = self.make_events(count=10)
        messages = Messages(seed=3)
        unknown = b"\x01\x02\x03\x04\x05\x06\x07\x08payload"
        mixed = [("UNKNOWN", unknown, 5), ("STATE_EST", messages.sensor(0), 6)]
        # Garbage between two events, and a last event cut short.
        cut = struct.pack(">Iqqii", SYNC, 99, 7, 9, 100) + b"STATE_EST" + b"\0" * 10
        write_log(self.path, events[:30] + mixed, tail=b"garbage!")
        with open(self.path, "ab") as f:
            for number, (channel, payload, stamp) in enumerate(events[30:], start=100):
                f.write(struct.pack(">Iqqii", SYNC, number, stamp, len(channel), len(payload)))
                f.write(channel.encode() + payload)
            f.write(cut)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            tables = stewart_log.read_log(self.path)
        texts = " | ".join(str(w.message) for w in caught)
        self.assertIn("UNKNOWN: 1 messages of a type this build does not define", texts)
        self.assertIn("STATE_EST: 1 messages not of type stewart.state_t", texts)
        self.assertIn("8 bytes of corrupt records skipped", texts)
        self.assertNotIn("UNKNOWN", tables)
        for channel, rows in expected.items():
            self.assert_table(channel, tables[channel], rows)
        log = stewart_log.read_events(self.path)
        self.assertTrue(log.truncated)
        self.assertEqual(log.skipped_bytes, 8)

    def test_cli_counts_channels(self):
        events, expected = self.make_events(count=20)
        write_log(self.path, events)
        result = subprocess.run([sys.executable, "-m", "stewart_log", self.path, "--decode"],
                                capture_output=True, text=True, check=True)
        lines = result.stdout.splitlines()
        first, last = events[0][2], events[-1][2]
        self.assertIn(f"{len(events)} messages on 7 channels over {(last - first) * 1e-6:.3f} s",
                      lines[0])
        for channel, (type_name, _) in CHANNELS.items():
            line = next(l for l in lines if l.split()[0] == channel)
            self.assertEqual(line.split()[1:3], [type_name, str(len(expected[channel]))])
        self.assertIn("read_log: 7 tables", result.stdout)


if __name__ == "__main__":
    unittest.main()
