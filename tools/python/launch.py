"""The one launcher of `dhpd run` for study and stress: --set overrides, wall time, peak memory."""
import json
import os
import subprocess
import threading
import time
from dataclasses import dataclass

import run_folder


# Peak memory. os.wait4's ru_maxrss is no measure of the engine: Linux starts a child's maxrss
# from the launcher's own resident size at fork and keeps the larger across exec, so a Python
# driver of 168 MiB reported 168 MiB for a run that peaks at 64 MB. The child's own high-water
# mark is taken instead: summary.json's `peak_memory_mb` (the engine's VmHWM at its end) when
# the run wrote one, else VmHWM of /proc/PID/status polled while the child runs (its last value
# before the exit; only readings taken after the exec, when the process is the engine, count).
# The poll starts every 2 ms and slows to every 50 ms after a few seconds, so growth in the last
# interval before the exit can be missed: for runs of a few ms the number is a lower bound.
POLL_FIRST, POLL_LAST = 0.002, 0.05
SOURCE_SUMMARY = "summary.json peak_memory_mb"
SOURCE_PROC = "/proc VmHWM (polled)"


@dataclass
class Launch:
    """What one `dhpd run` gave: its exit code (-1 when stopped at the timeout), its stderr, wall
    seconds, the child's own peak resident memory in MiB (None when unknown) and where that
    number comes from, and summary.json (None when the run wrote none that reads)."""
    code: int
    stderr: str
    wall: float
    peak_mib: float
    summary: dict = None
    timed_out: bool = False
    peak_source: str = "unknown"


def set_arguments(overrides):
    """`--set key=value` for each override; lists and maps as JSON, other values as str()."""
    args = []
    for key, value in (overrides or {}).items():
        text = json.dumps(value) if isinstance(value, (list, dict)) else str(value)
        args += ["--set", f"{key}={text}"]
    return args


def command(dhpd, scene, out_dir, overrides=None, threads=None, quiet=True):
    """The argument list of `dhpd run SCENE --out DIR [--quiet] [--threads N] [--set k=v ...]`."""
    cmd = [dhpd, "run", scene, "--out", out_dir] + (["--quiet"] if quiet else [])
    if threads:
        cmd += ["--threads", str(threads)]
    return cmd + set_arguments(overrides)


def readable_summary(out_dir):
    try:
        return run_folder.load_summary(out_dir)
    except (OSError, ValueError):
        return None


def high_water_mib(pid, name):
    """VmHWM of /proc/PID/status in MiB while the process is `name` (its comm); None else."""
    try:
        with open(f"/proc/{pid}/status") as f:
            fields = dict(line.split(":", 1) for line in f if ":" in line)
    except OSError:
        return None
    if fields.get("Name", "").strip() != name[:15] or "VmHWM" not in fields:
        return None
    return float(fields["VmHWM"].split()[0]) / 1024.0


def watch_memory(pid, name, done, peak):
    """Polls the child's VmHWM until `done` is set; peak[0] holds the last reading."""
    start = time.monotonic()
    while not done.is_set():
        value = high_water_mib(pid, name)
        if value is not None:
            peak[0] = value
        done.wait(min(POLL_LAST, POLL_FIRST + (time.monotonic() - start) / 100.0))


def peak_memory(summary, polled):
    """(MiB, source): the run's own peak_memory_mb when its summary has one, else the polled
    VmHWM, else (None, 'unknown')."""
    value = (summary or {}).get("peak_memory_mb")
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value > 0:
        return float(value), SOURCE_SUMMARY
    if polled is not None:
        return polled, SOURCE_PROC
    return None, "unknown"


def run(dhpd, scene, out_dir, overrides=None, threads=None, quiet=True, env=None, timeout=None):
    """Runs dhpd (stdout discarded, stderr kept), watching its own peak memory (see above);
    after `timeout` seconds the child is killed."""
    cmd = command(dhpd, scene, out_dir, overrides, threads, quiet)
    killed, done, peak = threading.Event(), threading.Event(), [None]
    start = time.monotonic()
    with subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                          env=env) as proc:
        errors = []  # read while the child runs, so a full pipe cannot block it
        reader = threading.Thread(target=lambda: errors.append(proc.stderr.read()))
        reader.start()
        watcher = threading.Thread(target=watch_memory, args=(
            proc.pid, os.path.basename(dhpd), done, peak))
        watcher.start()

        def stop():
            killed.set()
            proc.kill()
        timer = threading.Timer(timeout, stop) if timeout else None
        if timer:
            timer.start()
        proc.wait()
        wall = time.monotonic() - start
        done.set()
        if timer:
            timer.cancel()
        reader.join()
        watcher.join()
    timed_out = killed.is_set() and proc.returncode < 0
    summary = readable_summary(out_dir)
    peak_mib, source = peak_memory(summary, peak[0])
    return Launch(-1 if timed_out else proc.returncode, "".join(errors), wall, peak_mib, summary,
                  timed_out, source)
