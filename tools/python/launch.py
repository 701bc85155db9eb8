"""The one launcher of `dhpd run` for study and stress: --set overrides, wall time, peak memory."""
import json
import os
import subprocess
import threading
import time
from dataclasses import dataclass

import run_folder


@dataclass
class Launch:
    """What one `dhpd run` gave: its exit code (-1 when stopped at the timeout), its stderr, wall
    seconds, the child's own peak resident memory in MiB and summary.json (None when the run
    wrote none that reads)."""
    code: int
    stderr: str
    wall: float
    peak_mib: float
    summary: dict = None
    timed_out: bool = False


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


def run(dhpd, scene, out_dir, overrides=None, threads=None, quiet=True, env=None, timeout=None):
    """Runs dhpd (stdout discarded, stderr kept) and waits for it with os.wait4, so the peak
    memory is this child's own; after `timeout` seconds the child is killed."""
    cmd = command(dhpd, scene, out_dir, overrides, threads, quiet)
    killed = threading.Event()
    start = time.monotonic()
    with subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                          env=env) as proc:
        errors = []  # read while the child runs, so a full pipe cannot block it
        reader = threading.Thread(target=lambda: errors.append(proc.stderr.read()))
        reader.start()

        def stop():
            killed.set()
            proc.kill()
        timer = threading.Timer(timeout, stop) if timeout else None
        if timer:
            timer.start()
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.monotonic() - start
        if timer:
            timer.cancel()
        proc.returncode = os.waitstatus_to_exitcode(status)
        reader.join()
    timed_out = killed.is_set() and os.WIFSIGNALED(status)
    code = -1 if timed_out else proc.returncode
    return Launch(code, "".join(errors), wall, usage.ru_maxrss / 1024.0,
                  readable_summary(out_dir), timed_out)
