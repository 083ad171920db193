#!/usr/bin/python3
"""Report of one run of the stack (tools/launch.sh): what went wrong first (an
incomplete log, a process that stopped reporting, a run the launcher did not
finish), the limits (on ground truth, or on the estimate with its
uncertainty when the log has no truth; what the config limits and what it
does not), the supervisor, every process's health, filter activity, filter
compute time, sensor-to-command latency, the closed form against the QP
reference on the recorded inputs, and the paper's Fig. 5 equivalent. Reads
<run>/csv/*.csv, <run>/config.yaml, <run>/run.yaml, <run>/log_continuity.json
(stewart_log_export) and <run>/replay/{closed_form,qp}.{json,csv}
(stewart_replay), all made by tools/report.sh.

Usage: tools/plots/report.py RUN_FOLDER    (Debian's /usr/bin/python3)
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

AXES = ["x", "y", "z", "phi", "theta", "psi"]
CASES = {0: "none", 1: "position", 2: "velocity", 3: "both", 4: "infeasible", 5: "fallback"}


def load(run, channel_key, config):
    lcm = config["lcm"]
    name = lcm["channel_prefix"] + lcm["channels"][channel_key] + (lcm.get("channel_suffix") or "")
    path = os.path.join(run, "csv", name + ".csv")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return None
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]
            if k not in ("name", "counters", "counter_deltas", "last_error", "latched_error")}


SEVERITY = {2: 1, 3: 2}  # DEGRADED, FAULT; the other states are no problem
HEALTH_STATES = {0: "STARTING", 1: "OK", 2: "DEGRADED", 3: "FAULT", 4: "STOPPED"}
STATE_STOPPED = 4
PLANTS = ("plant_sim", "hw_bridge")
# With the estimate as the only source, a value counts as beyond a limit only
# when it is beyond it by more than this many of the estimate's own standard
# deviations (q_std, qd_std of that sample).
ESTIMATE_SIGMAS = 3.0


def channel_path(run, config, key, suffix=".csv"):
    lcm = config["lcm"]
    name = lcm["channel_prefix"] + lcm["channels"][key] + (lcm.get("channel_suffix") or "")
    return os.path.join(run, "csv", name + suffix)


def parse_counters(text):
    return dict(item.split("=", 1) for item in (text or "").split(";") if "=" in item)


def heartbeats(run, config):
    """Every recorded heartbeat (health_t rows), per process in log order; {} without them."""
    path = channel_path(run, config, "health")
    if not os.path.exists(path):
        return {}
    rows = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            rows.setdefault(row["name"], []).append(row)
    return rows


def log_span_us(run, config, continuity):
    """First and last receive time (us) of the log: from the continuity check, else from the
    recorded channels' CSVs."""
    if continuity:
        return continuity["log_first_utime_us"], continuity["log_last_utime_us"]
    first, last = None, None
    folder = os.path.join(run, "csv")
    for name in os.listdir(folder) if os.path.isdir(folder) else []:
        if not name.endswith(".csv") or name.count(".") > 1:
            continue
        with open(os.path.join(folder, name)) as f:
            rows = list(csv.DictReader(f))
        if rows and "log_utime_us" in rows[0]:
            first = min(first, int(rows[0]["log_utime_us"])) if first else int(rows[0]["log_utime_us"])
            last = max(last or 0, int(rows[-1]["log_utime_us"]))
    return first or 0, last or 0


def restarts_of(beats):
    """Heartbeat seq falling back: the process started again (a new process, same name)."""
    return [b for prev, b in zip(beats, beats[1:]) if int(b["seq"]) <= int(prev["seq"])]


def process_ends(run, config, continuity):
    """Per process: how its reporting ended. 'stopped' (its last heartbeat says STOPPED),
    'silent' (no STOPPED heartbeat and silent for more than 2.5 heartbeat periods before the
    log ends: it died, was killed or hung), 'unfinished' (plant_sim ends a run by itself, so
    without a STOPPED heartbeat it did not finish), or 'to the end'."""
    rows = heartbeats(run, config)
    _, log_last = log_span_us(run, config, continuity)
    period_us = 1e6 / float(config.get("rates", {}).get("health_hz", 2.0))
    ends = {}
    for process, beats in rows.items():
        last = beats[-1]
        silent_us = log_last - int(last["log_utime_us"])
        if int(last["state"]) == STATE_STOPPED:
            ends[process] = ("stopped", last, silent_us)
        elif silent_us > 2.5 * period_us:
            ends[process] = ("silent", last, silent_us)
        elif process == "plant_sim":
            ends[process] = ("unfinished", last, silent_us)
        else:
            ends[process] = ("to the end", last, silent_us)
    return ends


def describe_end(process, end, t_of):
    kind, last, silent_us = end
    state = HEALTH_STATES.get(int(last["state"]), last["state"])
    at = t_of(last)
    if kind == "stopped":
        return f"exited normally (STOPPED heartbeat at {at})"
    if kind == "silent":
        return (f"**stopped reporting** at {at} (its last heartbeat, state {state}), "
                f"{silent_us * 1e-6:.1f} s before the log ends, without a STOPPED heartbeat: "
                f"it died, was killed or hung")
    if kind == "unfinished":
        return (f"**did not finish**: its last heartbeat ({at}, state {state}) is not STOPPED, "
                f"and plant_sim ends a run by itself: it died or was killed")
    return f"reported to the end of the log (last heartbeat at {at}, state {state})"


def health_section(run, config, t_of, continuity):
    """Per process, from all its heartbeats: the worst state during the run (each heartbeat
    carries the worst since the previous one), whether a fault latched, its rejections and
    restarts, how its reporting ended, and the counters of its last heartbeat."""
    rows = heartbeats(run, config)
    if not rows or "worst_state" not in next(iter(rows.values()))[0]:
        return []  # recorded before heartbeats carried the worst state
    ends = process_ends(run, config, continuity)
    lines = ["## Process health", "",
             "From every heartbeat: the worst state between two heartbeats, whether a FAULT "
             "latched (and what it was), rejected inputs in total and those with an "
             "implausible time, restarts (the heartbeat's seq fell back: a new process under "
             "the same name) and how its reporting ended (docs/operations.md, \"Health\"). "
             "Times t are stack times (the heartbeat's utime, its newest input).", "",
             "| process | worst state | fault latched | rejected | time implausible | restarts "
             "| end |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for process, beats in sorted(rows.items()):
        severity = max(SEVERITY.get(int(b["worst_state"]), 0) for b in beats)
        worst = {2: "FAULT", 1: "degraded", 0: "ok"}[severity]
        latched = [b for b in beats if b["fault_latched"] == "1"]
        last = beats[-1]
        counters = parse_counters(last["counters"])
        implausible = sum(int(v) for k, v in counters.items() if k.endswith("_time_implausible"))
        latched_text = f"yes: {latched[0]['latched_error']}" if latched else "no"
        restarts = restarts_of(beats)
        restart_text = (f"{len(restarts)} (first at {t_of(restarts[0])})"
                        if restarts else "0")
        lines.append(f"| {process} | {worst} | {latched_text} | {last['rejected_inputs']} | "
                     f"{implausible} | {restart_text} | "
                     f"{describe_end(process, ends[process], t_of)} |")
    faults = []
    for process, beats in sorted(rows.items()):
        seen = []
        for b in beats:
            for error in (b["latched_error"], b["last_error"] if int(b["state"]) == 3 else ""):
                if error and error not in seen:
                    seen.append(error)
                    faults.append(f"- {process}, {t_of(b)}: {error}")
    lines += ["", "Faults (each distinct error of a FAULT or a latched fault, first seen): "
              + ("none." if not faults else ""), *faults]
    lines += ["", "Counters of each process's last heartbeat (since its start; the time is "
              "that heartbeat's):", ""]
    for process, beats in sorted(rows.items()):
        last = beats[-1]
        counters = parse_counters(last["counters"])
        text = ", ".join(f"{k} {v}" for k, v in counters.items()) or "none"
        lines.append(f"- {process} ({t_of(last)}): messages in {last['messages_in']}, "
                     f"out {last['messages_out']}, rejected {last['rejected_inputs']}; {text}")
    return lines + [""]


SUPERVISOR_STATES = {0: "DISARMED", 1: "ARMING", 2: "ARMED", 3: "HOLD", 4: "ESTOP"}


def supervisor_rows(run, config):
    """The recorded supervisor_state_t rows (the log export's CSV), [] without them."""
    lcm = config["lcm"]
    channel = lcm["channels"].get("supervisor")
    if not channel:
        return []
    name = lcm["channel_prefix"] + channel + (lcm.get("channel_suffix") or "")
    path = os.path.join(run, "csv", name + ".csv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def supervisor_t_s(row, t0):
    """A supervisor row's stack time from the first state (s); one made before the supervisor
    saw any state (utime 0: power-on) counts as the start."""
    utime = int(row["utime_us"])
    return (utime - t0) * 1e-6 if utime > 0 else 0.0


def supervisor_section(run, config, t0):
    """The supervisor's states through the run (docs/operations.md, "Arming and e-stop"):
    each change with its stack time and reason, from the recorded supervisor_state_t; the
    HOLDs and ESTOPs counted with their reasons."""
    rows = supervisor_rows(run, config)
    if not rows:
        return []
    lines = ["## Supervisor", "",
             "State changes of the supervisor (stack time of the decision from the first "
             "state, as every t of this report; docs/operations.md, \"Arming and e-stop\"). "
             "The motion clock is the stack time spent ARMING or ARMED.",
             "", "| t (s) | state | reason |", "| --- | --- | --- |"]
    previous = None
    stops = []
    for row in rows:
        key = (row["state"], row["transitions"])
        if key == previous:
            continue
        previous = key
        t = supervisor_t_s(row, t0)
        state = SUPERVISOR_STATES.get(int(row["state"]), row["state"])
        lines.append(f"| {t:.3f} | {state} | {row['reason']} |")
        if state in ("HOLD", "ESTOP"):
            stops.append(f"{state} at {t:.3f} s ({row['reason'] or 'no reason given'})")
    last = rows[-1]
    lines += ["", f"HOLD / ESTOP: {len(stops)}" + (": " + "; ".join(stops) if stops else "") + ".",
              "", f"At the end: {SUPERVISOR_STATES.get(int(last['state']), last['state'])}, "
              f"motion clock {int(last['motion_time_us']) * 1e-6:.3f} s, operator commands "
              f"accepted {last['operator_commands_accepted']}, rejected "
              f"{last['operator_commands_rejected']}.", ""]
    return lines


def recording_section(continuity):
    """How complete the log is, from the seq numbers of its streams (stewart_log_export
    --continuity-json): messages published but not recorded, and publishers that restarted."""
    if not continuity:
        return ["## Recording", "", "Not checked: no log_continuity.json (tools/report.sh "
                "writes it with stewart_log_export).", ""], []
    first = continuity["log_first_utime_us"]
    published = continuity["recorded"] + continuity["missing"]
    lines = ["## Recording", ""]
    warnings = []
    if continuity["missing"] == 0 and continuity["restarts"] == 0:
        lines += [f"Complete: {continuity['recorded']} numbered messages in "
                  f"{len(continuity['streams'])} streams, no gap in any seq.", ""]
        return lines, warnings
    if continuity["missing"]:
        share = 100.0 * continuity["missing"] / published
        text = (f"the log lacks {continuity['missing']} of {published} published messages "
                f"({share:.1f} %): every number below that counts messages is short by them "
                f"(docs/operations.md, \"Logging\")")
        warnings.append(text)
        lines += [f"**Incomplete**: {text}.", ""]
    if continuity["restarts"]:
        text = f"{continuity['restarts']} publisher restart(s) during the run (seq fell back)"
        warnings.append(text)
        lines += [f"**{text[0].upper() + text[1:]}.**", ""]
    lines += ["| stream | recorded | missing | gaps | restarts | first event |",
              "| --- | --- | --- | --- | --- | --- |"]
    for name, st in continuity["streams"].items():
        if not st["missing"] and not st["restarts"]:
            continue
        event = next((e for e in continuity["events"] if e["stream"] == name), None)
        where = (f"{event['kind']} at log +{(event['log_utime_us'] - first) * 1e-6:.3f} s "
                 f"(utime {event['utime_us']}, seq {event['previous_seq']} -> {event['seq']})"
                 if event else f"(not among the first {len(continuity['events'])} events listed)")
        lines.append(f"| {name} | {st['recorded']} | {st['missing']} | {st['gaps']} | "
                     f"{st['restarts']} | {where} |")
    return lines + [""], warnings


def plant_last_heartbeat(run, config):
    """The plant process's (plant_sim or hw_bridge) last heartbeat row, or None."""
    rows = heartbeats(run, config)
    for name in PLANTS:
        if name in rows:
            return rows[name][-1]
    return None


def limits_section(state, on_truth, safety, t):
    """Every configured limit against the state: on ground truth, the maximum reached and by
    how much it was exceeded; on the estimate (no truth), a value beyond a limit counts only
    when it is beyond by more than ESTIMATE_SIGMAS of the estimate's own standard deviation at
    that sample, and is reported "on the estimate". Then every side of every axis the config
    does not limit, with the extreme reached."""
    if on_truth:
        lines = ["## Limits, judged on ground truth (STATE_TRUE)", "",
                 "| constraint | limit | max reached | exceeded by |", "| --- | --- | --- | --- |"]
    else:
        lines = ["## Limits, judged on the estimate (STATE_EST): no ground truth in this log", "",
                 f"Without ground truth only the estimate is there to judge by: a limit counts as "
                 f"exceeded on the estimate when the estimate is beyond it by more than "
                 f"{ESTIMATE_SIGMAS:g} of its own standard deviations (q_std, qd_std) at that "
                 f"sample; a smaller excess is within the estimate's uncertainty, not a finding "
                 f"about the platform.", "",
                 "| constraint | limit | max reached (estimate) | beyond by | beyond by, in "
                 "sigmas (max) | verdict |", "| --- | --- | --- | --- | --- | --- |"]
    exceeded, uncertain, limited = [], [], set()
    for kind, key in (("position", "q"), ("velocity", "qd")):
        for limit in safety.get(f"{kind}_limits") or []:
            axis = limit["axis"]
            linear = AXES.index(axis) < 3
            unit = ({"q": "m", "qd": "m/s"} if linear else {"q": "rad", "qd": "rad/s"})[key]
            suffix = ({"q": "m", "qd": "mps"} if linear else {"q": "rad", "qd": "radps"})[key]
            values = state[f"{key}_{axis}_{suffix}"]
            std = state.get(f"{key}_std_{axis}_{suffix}")
            for side in ("upper", "lower"):
                if side not in limit:
                    continue
                limited.add((axis, kind, side))
                bound = limit[side]
                reached = values.max() if side == "upper" else values.min()
                over = (reached - bound) if side == "upper" else (bound - reached)
                name = f"{axis} {kind} {side}"
                if on_truth:
                    lines.append(f"| {name} | {bound:g} {unit} | {reached:.5f} | "
                                 f"{max(over, 0.0):.2e} |")
                    if over > 0:
                        exceeded.append(name)
                    continue
                beyond = (values - bound) if side == "upper" else (bound - values)
                if std is not None:
                    sigmas = np.where(std > 0, beyond / np.where(std > 0, std, 1.0),
                                      np.where(beyond > 0, np.inf, 0.0))
                else:
                    sigmas = np.where(beyond > 0, np.inf, 0.0)
                worst_sigma = float(sigmas.max()) if len(sigmas) else 0.0
                if over <= 0:
                    verdict = "within"
                elif worst_sigma > ESTIMATE_SIGMAS:
                    verdict = "exceeded on the estimate"
                    exceeded.append(name)
                else:
                    verdict = f"within the estimate's uncertainty ({ESTIMATE_SIGMAS:g} sigma)"
                    uncertain.append(name)
                lines.append(f"| {name} | {bound:g} {unit} | {reached:.5f} | "
                             f"{max(over, 0.0):.2e} | {max(worst_sigma, 0.0):.2f} | {verdict} |")
    if on_truth:
        lines += ["", "Exceeded: " + (", ".join(exceeded) or "none") + " (on ground truth)"]
    else:
        lines += ["", "Exceeded on the estimate (by more than its uncertainty): "
                  + (", ".join(exceeded) or "none"),
                  "", "Beyond a limit within the estimate's uncertainty (not judged): "
                  + (", ".join(uncertain) or "none")]
    unlimited = []
    for kind, key in (("position", "q"), ("velocity", "qd")):
        for axis in AXES:
            linear = AXES.index(axis) < 3
            unit = ({"q": "m", "qd": "m/s"} if linear else {"q": "rad", "qd": "rad/s"})[key]
            suffix = ({"q": "m", "qd": "mps"} if linear else {"q": "rad", "qd": "radps"})[key]
            values = state[f"{key}_{axis}_{suffix}"]
            for side in ("upper", "lower"):
                if (axis, kind, side) in limited:
                    continue
                reached = values.max() if side == "upper" else values.min()
                unlimited.append(f"{axis} {kind} {side} ({'max' if side == 'upper' else 'min'} "
                                 f"{reached:.4g} {unit})")
    lines += ["", "Not limited by the config (safety.position_limits, safety.velocity_limits "
              "have no such bound), so never \"exceeded\"; the extreme reached on the "
              + ("ground truth" if on_truth else "estimate") + ": "
              + (", ".join(unlimited) or "none") + ".", ""]
    return lines


def percentile(values, p):
    return float(np.percentile(values, p)) if len(values) else float("nan")


def load_replay(run, variant):
    """stewart_replay's JSON and per-step CSV for one variant, or (None, None)."""
    json_path = os.path.join(run, "replay", variant + ".json")
    csv_path = os.path.join(run, "replay", variant + ".csv")
    if not (os.path.exists(json_path) and os.path.exists(csv_path)):
        return None, None
    with open(json_path) as f:
        summary = json.load(f)
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    forces = {int(r["sample_utime_us"]): np.array([float(r[f"f_replayed{i}_n"]) for i in range(6)])
              for r in rows}
    return summary, forces


def us(ns):
    return "n/a" if ns is None else f"{ns / 1e3:.2f} us"


def replay_section(run):
    """Closed form vs QP reference, both replayed offline on the recorded inputs."""
    lines = ["## Closed form vs QP reference", ""]
    cf, cf_forces = load_replay(run, "closed_form")
    qp, qp_forces = load_replay(run, "qp")
    if cf is None or qp is None:
        reasons = []
        for name in ("missing.txt", "closed_form.txt", "qp.txt"):
            path = os.path.join(run, "replay", name)
            if os.path.exists(path):
                reasons.append(open(path).read().strip().splitlines()[-1:])
        why = "; ".join(r[0] for r in reasons if r) or "no replay output in replay/"
        return lines + [f"Not available: {why}.", ""]
    common = sorted(set(cf_forces) & set(qp_forces))
    diff = np.array([np.max(np.abs(cf_forces[k] - qp_forces[k])) for k in common])
    max_diff = float(diff.max()) if len(diff) else float("nan")
    worst = common[int(np.argmax(diff))] if len(diff) else None
    cf_s, qp_s = cf["safety"], qp["safety"]
    lines += [f"`stewart_replay` re-ran the safety process offline on the recorded state "
              f"estimates and nominal commands (in log order), once with the closed form and "
              f"once with the QP reference ({qp_s['qp_solver']}): {len(common)} safe commands; "
              f"the live filter was {cf_s['recorded_variant']}.", ""]
    lines += [f"- max |F_closed_form - F_qp| over every step: **{max_diff:.3g} N**"
              + (f" (at sample_utime {worst} us)" if worst is not None and max_diff > 0 else "")]
    verdict = "met" if max_diff < 1e-6 else "NOT met"
    lines += [f"- target (same forces, max difference below 1e-6 N): {verdict} "
              f"(measured {max_diff:.3g} N)", ""]
    lines += ["| filter | p50 | p99 | steps |", "| --- | --- | --- | --- |"]
    t_cf, t_qp = cf_s["compute_ns"]["replayed"], qp_s["compute_ns"]["replayed"]
    t_live = cf_s["compute_ns"]["recorded"]
    lines.append(f"| closed form (replay) | {us(t_cf['p50'])} | {us(t_cf['p99'])} | "
                 f"{t_cf['count']} |")
    lines.append(f"| QP reference (replay) | {us(t_qp['p50'])} | {us(t_qp['p99'])} | "
                 f"{t_qp['count']} |")
    lines.append(f"| {cf_s['recorded_variant']} (live node) | {us(t_live['p50'])} | "
                 f"{us(t_live['p99'])} | {t_live['count']} |")
    if t_cf["p50"] and t_qp["p50"] and t_cf["p99"] and t_qp["p99"]:
        lines += ["", f"QP reference / closed form: {t_qp['p50'] / t_cf['p50']:.1f}x at p50, "
                  f"{t_qp['p99'] / t_cf['p99']:.1f}x at p99."]
    n, same = cf_s["compared"], cf_s["identical"]
    fb = cf_s["fallback"]
    if cf_s["recorded_variant"] != "closed_form":
        reproduced = (f"not applicable: the live filter was {cf_s['recorded_variant']} "
                      f"({n - same} of {n} commands differ from the closed form, max "
                      f"{cf_s['max_abs_diff_n']:.3g} N)")
    elif n and same == n:
        reproduced = f"yes, bit-identical on all {n} filter commands"
    else:
        reproduced = (f"no: {n - same} of {n} filter commands differ, max |dF| "
                      f"{cf_s['max_abs_diff_n']:.3g} N")
    lines += ["", f"Closed-form replay reproduces the recorded commands: {reproduced}. "
              f"Fallback commands of the live node are not filter outputs and are counted "
              f"apart: {fb['recorded']} ({fb['stale_input']} stale input, {fb['invalid_state']} "
              f"invalid state, {fb['by_filter']} filter last resort), {fb['identical']} of "
              f"{fb['compared']} replayed bit-identically.", ""]
    gaps = cf.get("log_gaps", {})
    if gaps:
        per_channel = ", ".join(f"{channel} {g['missing']}" for channel, g in gaps.items())
        lines += [f"The log lacks {sum(g['missing'] for g in gaps.values())} messages that were "
                  f"published but not recorded ({per_channel}; lcm-logger drops bursts, see "
                  f"docs/operations.md, Replay); they are not compared.", ""]
    return lines


def constraint_activity(run, config, diag, dt):
    """Time each constraint was active. The filter acts on the two composed
    conditions; a composed condition's correction is attributed to its
    barriers by their LSE weights w_i (they sum to 1): a barrier's active time
    is the sum of w_i * dt over the steps whose case activates its group. Also
    the steps where it dominated the composition (w_i >= 0.5). Variant
    uncomposed: the steps where the barrier's own multiplier is positive."""
    lcm = config["lcm"]
    name = lcm["channel_prefix"] + lcm["channels"]["safety_diagnostics"] + \
        (lcm.get("channel_suffix") or "")
    path = os.path.join(run, "csv", name + ".barriers.csv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        barriers = list(csv.DictReader(f))
    case = diag["active_case"]
    group_active = {"position": (case == 1) | (case == 3), "velocity": (case == 2) | (case == 3)}
    # Variant uncomposed has no composition: each barrier has its own
    # condition and multiplier, active when that multiplier is positive.
    uncomposed = "variant" in diag and len(diag["variant"]) > 0 and bool(np.all(diag["variant"] == 3))
    if uncomposed:
        lines = ["", "Time each constraint was active (variant uncomposed: its own condition's "
                 "multiplier mu_i > 0):", "",
                 "| constraint | group | active time (s) | active steps |", "| --- | --- | --- | --- |"]
    else:
        lines = ["", "Time each constraint was active (its LSE weight's share of the active "
                 "composed condition; dominant: weight >= 0.5 while active):", "",
                 "| constraint | group | active time (s) | dominant steps |",
                 "| --- | --- | --- | --- |"]
    for b in barriers:
        if uncomposed:
            column = f"mu_{b['group']}{b['index']}_"
            if column not in diag:
                continue
            steps = int(np.sum(diag[column] > 0))
            time_s, count = steps * dt, steps
        else:
            column = f"w_{b['group']}{b['index']}_"
            if column not in diag:
                continue
            w = diag[column]
            active = group_active[b["group"]]
            time_s = float(np.sum(w[active])) * dt
            count = int(np.sum(active & (w >= 0.5)))
        if time_s > 0 or count:
            lines.append(f"| {b['name']} | {b['group']} | {time_s:.2f} | {count} |")
    if len(lines) == 5:
        lines.append("| (none) | | 0 | 0 |")
    return lines


def main():
    run = sys.argv[1]
    with open(os.path.join(run, "config.yaml")) as f:
        config = yaml.safe_load(f)
    truth = load(run, "state_truth", config)
    est = load(run, "state_estimate", config)
    diag = load(run, "safety_diagnostics", config)
    sensors = load(run, "sensors", config)
    safe = load(run, "command_safe", config)
    setpoint = load(run, "setpoint", config)
    state = truth if truth is not None else est
    if state is None:
        sys.exit(f"report: {run}: the log has neither ground truth nor state estimates "
                 f"(channels {config['lcm']['channels']['state_truth']}, "
                 f"{config['lcm']['channels']['state_estimate']}): nothing to report on")
    on_truth = truth is not None
    t0 = state["utime_us"][0]
    t = (state["utime_us"] - t0) * 1e-6

    safety = config["safety"]
    run_info = {}
    run_yaml = os.path.join(run, "run.yaml")
    if os.path.exists(run_yaml):
        run_info = yaml.safe_load(open(run_yaml)) or {}
    continuity = None
    continuity_path = os.path.join(run, "log_continuity.json")
    if os.path.exists(continuity_path):
        with open(continuity_path) as f:
            continuity = json.load(f)
    log_first_us, _ = log_span_us(run, config, continuity)

    def t_of(row):
        """When a CSV row was: its stack time from the first state (a heartbeat's utime is its
        newest input), or its log time when it has none yet."""
        if int(row["utime_us"]) > 0:
            return f"t = {(int(row['utime_us']) - t0) * 1e-6:.3f} s"
        return (f"log +{(int(row['log_utime_us']) - log_first_us) * 1e-6:.3f} s "
                f"(before its first input)")

    # What went wrong, first: every such finding, then the sections.
    recording_lines, warnings = recording_section(continuity)
    if os.path.exists(run_yaml) and "wall_time_s" not in run_info:
        warnings.append("the launcher did not finish this run (run.yaml has no wall_time_s): "
                        "a process died or the run was interrupted; see the process logs")
    ends = process_ends(run, config, continuity)
    for process, end in sorted(ends.items()):
        if end[0] in ("silent", "unfinished"):
            warnings.append(f"{process} {describe_end(process, end, t_of)}"
                            + (f"; its log: {process}.log"
                               if os.path.exists(os.path.join(run, process + ".log")) else ""))
    if not on_truth:
        warnings.append("no ground truth in this log (on hardware there is none): the limits "
                        "are judged on the estimate, within its uncertainty")
    lines = ["# Run report", ""]
    if os.path.exists(run_yaml):
        lines += ["```", open(run_yaml).read().strip(), "```", ""]
    lines += ["## Warnings", ""] + ([f"- {w}" for w in warnings] if warnings else ["None."])
    lines += [""] + recording_lines
    lines += limits_section(state, on_truth, safety, t)
    lines += supervisor_section(run, config, t0)
    lines += health_section(run, config, t_of, continuity)

    if diag is not None:
        dt = np.median(np.diff(diag["utime_us"])) * 1e-6 if len(diag["utime_us"]) > 1 else 0.0
        lines += ["## Filter activity", "", "| case | steps | time (s) |", "| --- | --- | --- |"]
        for code, name in CASES.items():
            n = int(np.sum(diag["active_case"] == code))
            if n:
                lines.append(f"| {name} | {n} | {n * dt:.2f} |")
        lines += constraint_activity(run, config, diag, dt)
        ns = diag["compute_ns"]
        lines += ["", f"Filter compute time per step: p50 {percentile(ns, 50) / 1e3:.2f} us, "
                  f"p99 {percentile(ns, 99) / 1e3:.2f} us, max {ns.max() / 1e3:.2f} us "
                  f"({len(ns)} steps).", ""]

    if sensors is not None and safe is not None:
        # Log receive times of a sample and of the safe command derived from it.
        sample_rx = dict(zip(sensors["sample_utime_us"], sensors["log_utime_us"]))
        lat = [rx - sample_rx[s] for s, rx in zip(safe["sample_utime_us"], safe["log_utime_us"])
               if s in sample_rx]
        lat = np.array(lat)
        lines += ["## Sensor-to-command latency", "",
                  f"From the logger's receive time of a sensor sample to that of the safe "
                  f"command derived from it: p50 {percentile(lat, 50):.0f} us, p99 "
                  f"{percentile(lat, 99):.0f} us, max {lat.max():.0f} us over {len(lat)} "
                  f"commands; {len(sensors['seq']) - len(lat)} samples had no safe command.", ""]

    plant = plant_last_heartbeat(run, config)
    counters = parse_counters(plant["counters"]) if plant is not None else {}
    if sensors is not None and safe is not None and counters and "latency_p50_us" in counters:
        lines += [f"As the plant measures it (sample published to the first command derived "
                  f"from it received, both on the plant's clock, so it includes the plant's "
                  f"own wake-up; the logger's times above are the kernel's arrival times of "
                  f"the two datagrams): p50 "
                  f"{counters['latency_p50_us']} us, p99 {counters['latency_p99_us']} us, "
                  f"max {counters['latency_max_us']} us over "
                  f"{counters.get('answered_samples', '?')} answered samples.", ""]
    if plant is not None:
        end = ends.get(plant["name"])
        ending = describe_end(plant["name"], end, t_of) if end else ""
        known = [k for k in ("missed_ticks", "missed_stack_late", "missed_plant_late",
                             "overrun_ticks", "tick_late_p99_us", "tick_late_max_us",
                             "lockstep_resends", "command_timeouts", "endstop_hits", "ticks")
                 if k in counters]
        # hw_bridge has counters of its own (the device link's): all of them.
        keys = known or list(counters)
        shown = ", ".join(f"{k} {counters[k]}" for k in keys) or "none"
        lines += [f"Plant counters ({plant['name']}, its last heartbeat, at "
                  f"{t_of(plant)}, state "
                  f"{HEALTH_STATES.get(int(plant['state']), plant['state'])}; {ending}): "
                  f"{shown}."]
        if "missed_ticks" in counters:
            lines[-1] += (" missed_ticks: ticks whose previous sample got no command in time "
                          "(real time; includes the start-up before the stack answers), split "
                          "into missed_stack_late (the stack had at least half a period and did "
                          "not answer) and missed_plant_late (the plant itself published that "
                          "sample late, leaving the stack less than half a period).")
        lines.append("")

    lines += replay_section(run)

    fig, axes = plt.subplots(5, 3, figsize=(14, 13), sharex=True)
    limits = {(l["axis"], kind): l for kind in ("position", "velocity")
              for l in safety[f"{kind}_limits"]}
    for j, axis in enumerate(AXES[:3]):
        ax = axes[0, j]
        ax.plot(t, state[f"q_{axis}_m"], label=f"{axis}")
        if setpoint is not None:
            ax.plot((setpoint["utime_us"] - t0) * 1e-6, setpoint[f"q_des_{axis}_m"], "--",
                    lw=0.8, label=f"{axis}_des")
        if (axis, "position") in limits and "upper" in limits[(axis, "position")]:
            ax.axhline(limits[(axis, "position")]["upper"], color="r", lw=0.8, label="limit")
        ax.set_ylabel(f"{axis} (m)")
        ax.legend(fontsize=7)
        ax = axes[1, j]
        ax.plot(t, state[f"qd_{axis}_mps"])
        if (axis, "velocity") in limits and "upper" in limits[(axis, "velocity")]:
            ax.axhline(limits[(axis, "velocity")]["upper"], color="r", lw=0.8)
        ax.set_ylabel(f"d{axis}/dt (m/s)")
    if diag is not None:
        td = (diag["utime_us"] - t0) * 1e-6
        for i in range(6):
            axes[2, i % 3].plot(td, diag[f"f_safe{i}_n"], lw=0.8, label=f"F*{i}")
            axes[2, i % 3].plot(td, diag[f"f_des{i}_n"], lw=0.6, ls=":", label=f"F_des{i}")
        for j in range(3):
            axes[2, j].set_ylabel("leg force (N)")
            axes[2, j].legend(fontsize=6, ncol=2)
        axes[3, 0].plot(td, diag["active_case"], lw=0.8)
        axes[3, 0].set_yticks(list(CASES))
        axes[3, 0].set_yticklabels(list(CASES.values()), fontsize=7)
        axes[3, 0].set_ylabel("filter case")
        axes[3, 1].plot(td, diag["correction_norm_n"], lw=0.8)
        axes[3, 1].set_ylabel("||F* - F_des|| (N)")
        axes[3, 2].plot(td, diag["compute_ns"] / 1e3, lw=0.5)
        axes[3, 2].set_ylabel("filter time (us)")
    supervisor = supervisor_rows(run, config)
    if supervisor:
        ts = [supervisor_t_s(r, t0) for r in supervisor]
        axes[4, 0].step(ts, [int(r["state"]) for r in supervisor], where="post", lw=0.8)
    axes[4, 0].set_yticks(list(SUPERVISOR_STATES))
    axes[4, 0].set_yticklabels(list(SUPERVISOR_STATES.values()), fontsize=7)
    axes[4, 0].set_ylabel("supervisor")
    if diag is not None and "nominal_scale" in diag:
        axes[4, 1].plot(td, diag["nominal_scale"], lw=0.8)
    axes[4, 1].set_ylabel("nominal scale s\n(1: within the per-period bound)", fontsize=8)
    flag_bits = ((4, "fallback"), (2, "infeasible"), (128, "outside"), (256, "drive off"),
                 (512, "bounded"), (1024, "per barrier"))
    if diag is not None and "flags" in diag:
        flags = diag["flags"].astype(int)
        for row, (bit, _) in enumerate(flag_bits):
            axes[4, 2].step(td, row + 0.8 * ((flags & bit) != 0), where="post", lw=0.8)
    axes[4, 2].set_yticks([row + 0.4 for row in range(len(flag_bits))])
    axes[4, 2].set_yticklabels([label for _, label in flag_bits], fontsize=7)
    axes[4, 2].set_ylabel("command flags")
    for ax in axes[-1]:
        ax.set_xlabel("t (s)")
    fig.suptitle(f"Fig. 5 equivalent: {os.path.basename(os.path.normpath(run))}")
    fig.tight_layout()
    fig.savefig(os.path.join(run, "fig5.png"), dpi=100)
    lines += ["## Plots", "", "![Fig. 5 equivalent](fig5.png)", ""]
    with open(os.path.join(run, "report.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines[:40]))


if __name__ == "__main__":
    main()
