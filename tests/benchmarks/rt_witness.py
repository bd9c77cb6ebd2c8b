"""What tells a stall of the machine from one of ours in the real-time benchmarks.

A period of the 1 kHz loop is the step's wall time, the sleep to the next deadline and the
lateness of the wake-up after it. A step that runs long is ours. A wake-up that comes late is
the machine's when nothing of the machine's CPUs could run then either: ``Witness`` runs a
small C++ probe (``rt_probe.cpp``, compiled here once) with one thread per CPU at a real-time
priority above the loop's, waking every millisecond, and lists its own late wake-ups; a late
wake-up of the loop that the probe on its CPU shares is the host's (the virtual CPU was not
running: steal) or the kernel's, one it does not share is ours. Around a run, the steal time of
each CPU (/proc/stat), the load average, and the loop thread's page faults and context switches
(/proc/self/task) say more.

``realtime_attribution`` puts it together for one run of a ``RealTimeLoop``; the ``realtime``
benchmark (run.py) and the ``foxglove_live`` one (bench_export.py) both call it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

PROBE_SOURCE = Path(__file__).with_name("rt_probe.cpp")
# Above the loop's SCHED_FIFO 80 (so nothing of ours delays it), below the kernel's own 99.
PROBE_PRIORITY = 90
PROBE_THRESHOLD_US = 50
TICKS = os.sysconf("SC_CLK_TCK")


def rt_threads_elsewhere(exclude: set[int]) -> set[tuple[int, str, int]]:
    """Real-time threads of other user processes (pid, name, priority): another program's loop
    at or above ours takes the CPU from it unseen by the probe, which runs higher."""
    found = set()
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit() or int(proc.name) in exclude:
            continue
        try:
            tasks = list((proc / "task").iterdir())
        except OSError:
            continue
        for task in tasks:
            try:
                name, fields = (task / "stat").read_text().rsplit(")", 1)
            except OSError:
                continue
            fields = fields.split()
            kernel = int(fields[6]) & 0x00200000  # PF_KTHREAD
            if int(fields[38]) in (1, 2) and not kernel:  # SCHED_FIFO, SCHED_RR
                found.add((int(proc.name), name.split("(", 1)[1], int(fields[37])))
    return found


def pressure_stall_us(resource: str) -> int:
    """Microseconds some task of the machine stalled on `resource` (PSI), so far; 0 if absent."""
    try:
        line = Path(f"/proc/pressure/{resource}").read_text().splitlines()[0]
    except OSError:
        return 0
    return int(line.rsplit("total=", 1)[1])


def probe_binary() -> tuple[Path | None, str]:
    """The probe, compiled once per source version into the temporary folder; None and why
    when there is no C++ compiler."""
    compiler = shutil.which("c++") or shutil.which("g++")
    if compiler is None:
        return None, "no C++ compiler (c++ or g++) to build the witness probe"
    digest = hashlib.sha256(PROBE_SOURCE.read_bytes()).hexdigest()[:12]
    binary = Path(tempfile.gettempdir()) / f"ambfplus-rt-probe-{digest}"
    if not binary.exists():
        partial = binary.with_suffix(f".{os.getpid()}")
        subprocess.run(
            [compiler, "-O2", "-std=c++17", "-pthread", str(PROBE_SOURCE), "-o", str(partial)],
            check=True,
        )
        partial.replace(binary)
    return binary, ""


def cpu_steal() -> dict[int, float]:
    """Seconds each CPU's virtual processor was kept from running by the host, so far."""
    steal = {}
    with open("/proc/stat") as stat:
        for line in stat:
            name, *values = line.split()
            if name.startswith("cpu") and name != "cpu":
                steal[int(name[3:])] = int(values[7]) / TICKS
    return steal


class Witness:
    """The probe on every CPU while a `with` block runs; `.report`, `.late` and `.ok` after
    it. Without a compiler, or where the probe gets no real-time scheduling, `.ok` is False and
    `.report` says why."""

    def __init__(self):
        self.cpus = sorted(os.sched_getaffinity(0))
        self.late: dict[int, np.ndarray] = {}  # per CPU: rows of (deadline, lateness), s
        self.report: dict = {}
        self.ok = False
        self._process = None

    def __enter__(self) -> Witness:
        self._steal = cpu_steal()
        self._load = os.getloadavg()
        self._memory_stall = pressure_stall_us("memory")
        self._competitors: set = set()
        binary, why = probe_binary()
        if binary is None:
            self.report["witness"] = why
        else:
            self._process = subprocess.Popen(
                [str(binary), str(PROBE_PRIORITY), str(PROBE_THRESHOLD_US), *map(str, self.cpus)],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
            )  # fmt: skip
            if self._process.stdout.readline().strip() != "ready":
                raise RuntimeError("the witness probe did not start")
        self._watching = threading.Event()
        self._watcher = threading.Thread(target=self._watch, daemon=True)
        self._watcher.start()
        return self

    def align(self, loop_wakes_at: float) -> None:
        """Moves the probe's wake-ups half a period away from the loop's (one of which came at
        `loop_wakes_at`, CLOCK_MONOTONIC s), so that the witness rarely preempts a step."""
        if self._process is not None:
            self._process.stdin.write(f"phase {loop_wakes_at:.9f}\n")
            self._process.stdin.flush()

    def _watch(self) -> None:
        """Samples other programs' real-time threads every 2 s while the block runs."""
        exclude = {os.getpid()} | ({self._process.pid} if self._process else set())
        while True:
            self._competitors |= rt_threads_elsewhere(exclude)
            if self._watching.wait(2.0):
                return

    def __exit__(self, *exc) -> None:
        self._watching.set()
        self._watcher.join()
        self.report["rt_threads_elsewhere"] = sorted(self._competitors)
        self.report["memory_stall_ms"] = round(
            (pressure_stall_us("memory") - self._memory_stall) / 1e3, 1
        )
        steal = cpu_steal()
        self.report["steal_ms"] = {c: round(1e3 * (steal[c] - self._steal[c]), 1) for c in steal}
        self.report["load_average"] = [round(v, 2) for v in self._load]
        if self._process is None:
            return
        out, _ = self._process.communicate("", timeout=30)
        probes = json.loads(out)["probes"]
        self.report["witness"] = [p["scheduling"] for p in probes]
        self.report["witness_lateness_us"] = {
            p["cpu"]: {"p50": p["p50_us"], "p99": p["p99_us"], "max": p["max_us"]} for p in probes
        }
        for p in probes:
            self.late[p["cpu"]] = np.array(p["late"], dtype=float).reshape(-1, 2)
        self.ok = all("SCHED_FIFO" in p["scheduling"] for p in probes)

    def events(self, cpus) -> np.ndarray:
        """The probe's late wake-ups on these CPUs: rows of (deadline, lateness), s."""
        rows = [self.late[c] for c in cpus if c in self.late]
        return np.concatenate(rows) if rows else np.zeros((0, 2))


def loop_thread() -> int | None:
    """The thread id of this process's SCHED_FIFO thread (the real-time loop's), if any."""
    for task in Path("/proc/self/task").iterdir():
        try:
            fields = (task / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[38]) == 1:  # policy (field 41): SCHED_FIFO
            return int(task.name)
    return None


def thread_counters(tid: int | None) -> dict:
    """Page faults, context switches and timer slack of a thread of this process."""
    if tid is None:
        return {}
    task = Path(f"/proc/self/task/{tid}")
    fields = (task / "stat").read_text().rsplit(")", 1)[1].split()
    status = dict(
        line.split(":", 1) for line in (task / "status").read_text().splitlines() if ":" in line
    )
    counters = {
        "minor_faults": int(fields[7]),
        "major_faults": int(fields[9]),
        "voluntary_switches": int(status["voluntary_ctxt_switches"]),
        "involuntary_switches": int(status["nonvoluntary_ctxt_switches"]),
        "cpu_s": (int(fields[11]) + int(fields[12])) / TICKS,
    }
    try:
        counters["timer_slack_ns"] = int(Path(f"/proc/{tid}/timerslack_ns").read_text())
    except OSError:
        pass
    return counters


def step_anchors(world, first_index: int, seconds: float) -> list[tuple[float, int]]:
    """(time.monotonic(), steps) when the world's step count was seen to change, polled for
    `seconds`: the clock of the loop's steps read against CLOCK_MONOTONIC. A step counts itself
    as soon as it holds the world's lock, within microseconds of its start."""
    anchors, end = [], time.monotonic() + seconds
    seen = world.step_index
    while True:
        # The count first: a pause between the two readings then only loosens the bound.
        index = world.step_index
        now = time.monotonic()
        if index != seen:
            anchors.append((now, index - first_index))
            seen = index
        if now > end:
            return anchors


@contextlib.contextmanager
def anchored(world, first_index: int, witness=None):
    """Inside a running RealTimeLoop of `world` (whose first step was `first_index` + 1): the
    loop's steps against CLOCK_MONOTONIC at the start of the block (then the witness, if given,
    is put out of the loop's phase) and at its end. Yields the anchors, complete after the
    block, for realtime_attribution."""
    anchors = step_anchors(world, first_index, 0.02)
    if witness is not None:
        witness.align(loop_phase(anchors, 1e-3))
    yield anchors
    anchors += step_anchors(world, first_index, 0.02)


def attribution_fields(runs: list[dict]) -> dict:
    """A benchmark line's per-round attribution fields, from rounds that each hold
    realtime_attribution's result under "attribution"."""
    return {
        **{
            f"over_2ms_{whose}": [r["attribution"][f"over_2ms_{whose}"] for r in runs]
            for whose in ("host", "ours", "unknown")
        },
        "late": [r["attribution"]["late"] for r in runs],
        "lock_wait_max_verdict": [r["attribution"]["lock_wait_max_verdict"] for r in runs],
    }


def loop_phase(anchors: list[tuple[float, int]], period: float) -> float:
    """A CLOCK_MONOTONIC time at which the loop woke for a step, from anchors alone (steps
    taken as on time): within the lateness of its earliest wake-up."""
    return min(t - (n - 1) * period for t, n in anchors if n >= 1)


def first_step_time(periods: np.ndarray, anchors: list[tuple[float, int]]) -> float:
    """CLOCK_MONOTONIC time of the loop's first step, from the periods and the anchors: each
    anchor (t, n) bounds it from above by t - (start of step n-1 after the first); the
    tightest bound is off by the poll's granularity and the lock wait, microseconds."""
    starts = np.concatenate([[0.0], np.cumsum(periods)])
    bounds = [t - starts[n - 1] for t, n in anchors if 1 <= n <= len(starts)]
    return min(bounds)


def late_periods(stats: dict, first: float, period: float) -> list[dict]:
    """Each period over 2 ms split into what made it long: the step before it (its wall time,
    CPU time, and how far it ran past the next deadline) and the wake-up after it (how long
    after it was due the next step began). The wake-up's lateness comes from the periods
    themselves: a step n began late by L[n] = (start[n] - start[0]) - n * period + L[0], and
    the earliest step of the run is taken as on time."""
    p = np.asarray(stats["periods"], dtype=float)
    if stats["steps"] - 1 != len(p):
        raise RuntimeError("the run outlasted the loop's window of periods")
    starts = np.concatenate([[0.0], np.cumsum(p)])
    drift = starts - period * np.arange(len(starts))
    lateness = np.empty_like(drift)
    # A loop more than 50 periods behind starts afresh after that step: a new origin.
    cuts = [0, *(int(m) + 2 for m in np.nonzero(p > 50 * period)[0]), len(drift)]
    for a, b in zip(cuts[:-1], cuts[1:]):
        if a < b:
            lateness[a:b] = drift[a:b] - drift[a:b].min()
    rows = []
    for n, wall, cpu in zip(stats["late"], stats["late_step_wall"], stats["late_step_cpu"]):
        wake = float(min(lateness[n + 1], p[n] - wall))
        rows.append({
            "start": first + starts[n],
            "period": float(p[n]),
            "step_wall": float(wall),
            "step_cpu": float(cpu),
            "overrun": float(max(0.0, lateness[n] + wall - period)),
            "wake_late": max(0.0, wake),
            "woke": first + starts[n + 1],
        })  # fmt: skip
    return rows


def held_up(events: np.ndarray, start: float, end: float) -> float:
    """How long (s) within [start, end] the probe was held up: the union of its late
    wake-ups' spans [deadline, deadline + lateness] cut to that interval."""
    spans = sorted(
        (max(d, start), min(d + late, end)) for d, late in events if d < end and d + late > start
    )
    total, reach = 0.0, start
    for a, b in spans:
        a = max(a, reach)
        if b > a:
            total += b - a
            reach = b
    return total


def attribute(rows: list[dict], witness: Witness, cpus) -> None:
    """Marks each late period 'host' or 'ours' (or 'unknown' without a witness), with how much
    of it the machine took ('machine'): of the wake-up's lateness, all of it when the probe on
    the loop's CPU (`cpus`: those the loop may have run on) was held up for at least half of it
    (a stall may begin up to a period before the probe is due, and a CPU back from one first
    serves its interrupts), else the part the probe shared; plus the time within the step
    during which the probe was held up. While the probe, above the loop's priority, could not
    run, neither could the loop's own code: the CPU was the host's, an interrupt's, or in kernel
    code that does not yield (the loop's own page faults could be such code: their count is in
    the benchmark's line). A period that would still be over 2 ms without what the machine took
    is ours."""
    events = witness.events(cpus)
    for r in rows:
        due = r["woke"] - r["wake_late"]
        shared = held_up(events, due, r["woke"])
        wake_machine = r["wake_late"] if shared >= 0.5 * r["wake_late"] else shared
        step_machine = held_up(events, r["start"], r["start"] + r["step_wall"])
        r["machine"] = wake_machine + step_machine
        if not witness.ok:
            r["verdict"] = "unknown"
        else:
            r["verdict"] = "host" if r["period"] - r["machine"] <= 2e-3 else "ours"


def realtime_attribution(stats: dict, anchors, witness, scheduling: str) -> dict:
    """The late periods of a run, each split into the step's time and the wake-up's lateness
    and marked 'host' or 'ours' by the witness, and the figures that go with it. `anchors`
    are the loop's steps seen against CLOCK_MONOTONIC at its start and end (step_anchors),
    `scheduling` the loop's own account of it (RealTimeLoop.scheduling)."""
    periods = np.asarray(stats["periods"])
    first = first_step_time(periods, anchors)
    # The anchors at the end must agree with those at the start: the periods are then whole.
    last = max(n for _, n in anchors)
    drift = min(t - first - float(np.sum(periods[: n - 1])) for t, n in anchors if n >= last - 20)
    rows = late_periods(stats, first, 1e-3)
    pinned = re.search(r"pinned to CPU (\d+)", scheduling)
    cpus = [int(pinned.group(1))] if pinned else witness.cpus
    attribute(rows, witness, cpus)
    # The longest lock wait is the host's when it lies in the step of a late period during
    # which the witness, on any CPU (the holder's too), was held up for all of it but the
    # target; otherwise it is counted ours.
    wait, everywhere = stats["lock_wait_max"], witness.events(witness.cpus)
    wait_verdict = "within target" if wait <= 200e-6 else "ours" if witness.ok else "unknown"
    for r in rows:
        if wait_verdict == "ours" and r["step_wall"] >= wait:
            if held_up(everywhere, r["start"], r["start"] + r["step_wall"]) >= wait - 200e-6:
                wait_verdict = "host"
    if os.environ.get("AMBFPLUS_REALTIME_DUMP"):
        # Everything the attribution used, appended as one JSON line, to look into a verdict.
        with open(os.environ["AMBFPLUS_REALTIME_DUMP"], "a") as dump:
            late = {c: v.tolist() for c, v in witness.late.items()}
            dump.write(json.dumps({"first": first, "rows": rows, "witness": late}) + "\n")
    us = lambda v: round(v * 1e6, 1)  # noqa: E731
    verdicts = [r["verdict"] for r in rows]
    return {
        "over_2ms_host": verdicts.count("host"),
        "over_2ms_ours": verdicts.count("ours"),
        "over_2ms_unknown": verdicts.count("unknown"),
        "lock_wait_max_verdict": wait_verdict,
        # Each period over 2 ms: when (s into the run), how long, the step before it (wall, CPU,
        # off its CPU: lock wait or blocked, how far past the next deadline it ran), how late
        # the next step began after it was due, how much of it the witness on the loop's CPU
        # shared, and whose it is.
        "late": [
            {
                "at_s": round(r["start"] - first, 3),
                "period_us": us(r["period"]),
                "step_wall_us": us(r["step_wall"]),
                "step_cpu_us": us(r["step_cpu"]),
                "step_off_cpu_us": us(r["step_wall"] - r["step_cpu"]),
                "overrun_us": us(r["overrun"]),
                "wake_late_us": us(r["wake_late"]),
                "machine_us": us(r["machine"]),
                "verdict": r["verdict"],
            }
            for r in rows
        ],  # fmt: skip
        "clock_alignment_us": us(abs(drift)),
        **witness.report,
    }
