#!/usr/bin/python3
"""Report of one run of the stack (tools/launch.sh): limits against ground
truth, filter activity, filter compute time, sensor-to-command latency, the
closed form against the QP reference on the recorded inputs, and the paper's
Fig. 5 equivalent. Reads <run>/csv/*.csv, <run>/config.yaml and
<run>/replay/{closed_form,qp}.{json,csv} (stewart_replay, run by tools/report.sh).

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


def health_section(run, config):
    """Per process, from all its heartbeats: the worst state during the run (each heartbeat
    carries the worst since the previous one), whether a fault latched, and its rejections."""
    lcm = config["lcm"]
    name = lcm["channel_prefix"] + lcm["channels"]["health"] + (lcm.get("channel_suffix") or "")
    path = os.path.join(run, "csv", name + ".csv")
    if not os.path.exists(path):
        return []
    rows = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            rows.setdefault(row["name"], []).append(row)
    if not rows or "worst_state" not in next(iter(rows.values()))[0]:
        return []  # recorded before heartbeats carried the worst state
    lines = ["## Process health", "",
             "From every heartbeat: the worst state between two heartbeats, whether a FAULT "
             "latched (and what it was), rejected inputs in total and those with an "
             "implausible time (docs/operations.md, \"Health\").", "",
             "| process | worst state | fault latched | rejected | time implausible |",
             "| --- | --- | --- | --- | --- |"]
    for process, beats in sorted(rows.items()):
        severity = max(SEVERITY.get(int(b["worst_state"]), 0) for b in beats)
        worst = {2: "FAULT", 1: "degraded", 0: "ok"}[severity]
        latched = [b for b in beats if b["fault_latched"] == "1"]
        last = beats[-1]
        counters = dict(item.split("=", 1) for item in last["counters"].split(";") if "=" in item)
        implausible = sum(int(v) for k, v in counters.items() if k.endswith("_time_implausible"))
        latched_text = f"yes: {latched[0]['latched_error']}" if latched else "no"
        lines.append(f"| {process} | {worst} | {latched_text} | "
                     f"{last['rejected_inputs']} | {implausible} |")
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


def supervisor_section(run, config):
    """The supervisor's states through the run (docs/operations.md, "Arming and e-stop"):
    each change with its stack time and reason, from the recorded supervisor_state_t."""
    rows = supervisor_rows(run, config)
    if not rows:
        return []
    lines = ["## Supervisor", "",
             "State changes of the supervisor (stack time of the decision; docs/operations.md, "
             "\"Arming and e-stop\"). The motion clock is the stack time spent ARMING or ARMED.",
             "", "| t (s) | state | reason |", "| --- | --- | --- |"]
    previous = None
    for row in rows:
        key = (row["state"], row["transitions"])
        if key == previous:
            continue
        previous = key
        t = int(row["utime_us"]) * 1e-6
        lines.append(f"| {t:.3f} | {SUPERVISOR_STATES.get(int(row['state']), row['state'])} | "
                     f"{row['reason']} |")
    last = rows[-1]
    lines += ["", f"At the end: {SUPERVISOR_STATES.get(int(last['state']), last['state'])}, "
              f"motion clock {int(last['motion_time_us']) * 1e-6:.3f} s, operator commands "
              f"accepted {last['operator_commands_accepted']}, rejected "
              f"{last['operator_commands_rejected']}.", ""]
    return lines


def plant_counters(run, config):
    """Counters of the plant process (plant_sim or hw_bridge) from its last health message."""
    lcm = config["lcm"]
    name = lcm["channel_prefix"] + lcm["channels"]["health"] + (lcm.get("channel_suffix") or "")
    path = os.path.join(run, "csv", name + ".csv")
    if not os.path.exists(path):
        return {}
    last = None
    with open(path) as f:
        for row in csv.DictReader(f):
            if row["name"] in ("plant_sim", "hw_bridge"):
                last = row
    if last is None or not last["counters"]:
        return {}
    return dict(item.split("=", 1) for item in last["counters"].split(";") if "=" in item)


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
    source = "ground truth (STATE_TRUE)" if truth is not None else "estimate (STATE_EST)"
    t0 = state["utime_us"][0]
    t = (state["utime_us"] - t0) * 1e-6
    safety = config["safety"]
    lines = ["# Run report", ""]
    run_yaml = os.path.join(run, "run.yaml")
    if os.path.exists(run_yaml):
        lines += ["```", open(run_yaml).read().strip(), "```", ""]

    lines += [f"## Limits, measured on {source}", "",
              "| constraint | limit | max reached | exceeded by |", "| --- | --- | --- | --- |"]
    exceeded = []
    for kind, key, unit in (("position", "q", "m"), ("velocity", "qd", "m/s")):
        for limit in safety[f"{kind}_limits"]:
            axis = limit["axis"]
            col = f"{key}_{axis}_" + ({"q": "m", "qd": "mps"}[key] if AXES.index(axis) < 3 else
                                      {"q": "rad", "qd": "radps"}[key])
            values = state[col]
            for side in ("upper", "lower"):
                if side not in limit:
                    continue
                bound = limit[side]
                reached = values.max() if side == "upper" else values.min()
                over = (reached - bound) if side == "upper" else (bound - reached)
                lines.append(f"| {axis} {kind} {side} | {bound:g} {unit} | {reached:.5f} | "
                             f"{max(over, 0.0):.2e} |")
                if over > 0:
                    exceeded.append(f"{axis} {kind} {side}")
    lines += ["", "Exceeded: " + (", ".join(exceeded) if exceeded else "none"), ""]
    lines += supervisor_section(run, config)
    lines += health_section(run, config)

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

        counters = plant_counters(run, config)
        if counters and "latency_p50_us" in counters:
            lines += [f"As the plant measures it (sample published to the first command derived "
                      f"from it received, both on the plant's clock, so it includes the plant's "
                      f"own wake-up; the logger's times above are the kernel's arrival times of "
                      f"the two datagrams): p50 "
                      f"{counters['latency_p50_us']} us, p99 {counters['latency_p99_us']} us, "
                      f"max {counters['latency_max_us']} us over "
                      f"{counters.get('answered_samples', '?')} answered samples.", ""]
        if counters:
            keys = [k for k in ("missed_ticks", "missed_stack_late", "missed_plant_late",
                                "overrun_ticks", "tick_late_p99_us",
                                "tick_late_max_us", "lockstep_resends",
                                "command_timeouts", "endstop_hits", "ticks") if k in counters]
            lines += ["Plant counters at the end (its last health message): " +
                      ", ".join(f"{k} {counters[k]}" for k in keys) +
                      ". missed_ticks: ticks whose previous sample got no command in time "
                      "(real time; includes the start-up before the stack answers), split into "
                      "missed_stack_late (the stack had at least half a period and did not "
                      "answer) and missed_plant_late (the plant itself published that sample "
                      "late, leaving the stack less than half a period).", ""]

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
        ts = [(int(r["utime_us"]) - t0) * 1e-6 for r in supervisor]
        axes[4, 0].step(ts, [int(r["state"]) for r in supervisor], where="post", lw=0.8)
    axes[4, 0].set_yticks(list(SUPERVISOR_STATES))
    axes[4, 0].set_yticklabels(list(SUPERVISOR_STATES.values()), fontsize=7)
    axes[4, 0].set_ylabel("supervisor")
    if diag is not None and "nominal_scale" in diag:
        axes[4, 1].plot(td, diag["nominal_scale"], lw=0.8)
    axes[4, 1].set_ylabel("nominal scale s\n(1: within the per-period bound)", fontsize=8)
    flag_bits = ((4, "fallback"), (2, "infeasible"), (128, "outside"), (256, "drive off"),
                 (512, "bounded"))
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
