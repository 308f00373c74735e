"""Runs a command of a lab tool with its output in a log file; a failure names the log.

Shared by tools/rig_cross_validation.py and tools/leader_rod_sweep.py. Standard library only.
"""
import subprocess


def run_logged(command, log_path, who):
    """Runs `command` with stdout and stderr in log_path. Raises SystemExit naming `who`, the
    command and the log (with its last three lines) if it cannot start or exits non-zero."""
    try:
        with open(log_path, "w") as log:
            rc = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT).returncode
    except OSError as e:
        raise SystemExit(f"{who}: cannot run {command[0]}: {e}")
    if rc != 0:
        tail = open(log_path).read().strip().splitlines()[-3:]
        raise SystemExit(f"{who}: `{' '.join(command[:2])}` exited {rc} (log: {log_path})"
                         + "".join("\n  " + line for line in tail))
