"""Helpers of the sweep tests: a tiny sweep file, and a Ray cluster started with ``ray start``.

The cluster's processes are stopped by process id (those whose command line names the cluster's
temp dir or GCS port, and their descendants) rather than by ``ray stop``, which would also stop
every other Ray instance of the machine (e.g. a parallel test's local Ray).
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[2]


def ray_executable() -> str:
    """The ``ray`` command of the interpreter running the tests (next to ``sys.executable``), so
    that the tests work from a venv that is not activated; PATH only where it is not there."""
    beside = Path(sys.executable).parent / "ray"
    if beside.is_file():
        return str(beside)
    found = shutil.which("ray")
    if found is None:
        raise FileNotFoundError(f"no ray command next to {sys.executable} or on PATH")
    return found


def wait_until(condition, timeout_s: float, what: str, proc=None, log: Path | None = None):
    """Poll `condition` until it is true; fail naming `what` after `timeout_s`, or at once when
    `proc` has exited (with the tail of `log`)."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        tail = log.read_text()[-3000:] if log is not None and log.is_file() else ""
        assert proc is None or proc.poll() is None, f"exited before {what}:\n{tail}"
        assert time.monotonic() < deadline, f"no {what} after {timeout_s:.0f} s:\n{tail}"
        time.sleep(0.2)


def tiny_sweep(tmp_path: Path, seeds: list[int], **fixed: object) -> Path:
    """A sweep over `seeds` with a budget of seconds per trial (tiny nets, short episodes)."""
    data = {
        "base": str(REPO / "configs" / "irregular_terrain_ppo.yaml"),
        "fixed": {
            "vec_env.n_envs": 1,
            "env.max_episode_steps": 40,
            "ppo": {"n_steps": 64, "batch_size": 64, "n_epochs": 1},
            "policy": {"pi": [16], "vf": [16]},
            "train.total_timesteps": 128,
            "eval": {"freq": 64, "n_episodes": 1},
            "checkpoint.freq": 64,
            **fixed,
        },
        "space": {"train.seed": {"grid": seeds}},
    }
    path = tmp_path / "tiny_sweep.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _children() -> dict[int, list[int]]:
    tree: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        with contextlib.suppress(OSError, ValueError, IndexError):
            fields = stat.read_text().rsplit(")", 1)[1].split()
            tree.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    return tree


def _matching_pids(needles: list[str]) -> set[int]:
    found = set()
    for cmd in Path("/proc").glob("[0-9]*/cmdline"):
        with contextlib.suppress(OSError):
            text = cmd.read_bytes().replace(b"\0", b" ").decode(errors="replace")
            if any(n in text for n in needles):
                found.add(int(cmd.parent.name))
    found.discard(os.getpid())
    tree, todo = _children(), list(found)
    while todo:
        for child in tree.get(todo.pop(), []):
            if child not in found:
                found.add(child)
                todo.append(child)
    return found


def stop_processes(needles: list[str], grace_s: float = 10.0) -> None:
    pids = _matching_pids(needles)
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in pids:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, sig)
        deadline = time.monotonic() + grace_s
        while pids and time.monotonic() < deadline:
            pids = {p for p in pids if not is_gone(p)}
            time.sleep(0.2)


def is_gone(pid: int) -> bool:
    """The process has exited (no longer in /proc, or a zombie waiting to be reaped)."""
    with contextlib.suppress(OSError):
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    return True


@contextlib.contextmanager
def loopback_cluster(nodes: int = 2, cpus_per_node: int = 1) -> Iterator[tuple[str, dict]]:
    """``ray start --head`` on 127.0.0.1 plus ``nodes - 1`` ``ray start --address`` workers.

    Yields (address, environment for drivers). Token authentication with a fresh random token,
    shared by the nodes and the driver through RAY_AUTH_TOKEN.
    """
    port = free_port()
    address = f"127.0.0.1:{port}"
    temp_dir = tempfile.mkdtemp(prefix="rayc", dir="/tmp")  # short: Unix socket path limit
    env = {
        **os.environ,
        "RAY_AUTH_MODE": "token",
        "RAY_AUTH_TOKEN": secrets.token_hex(32),
        "RAY_USAGE_STATS_ENABLED": "0",
    }
    common = ["--node-ip-address", "127.0.0.1", "--num-cpus", str(cpus_per_node)]
    try:
        subprocess.run(
            [ray_executable(), "start", "--head", "--port", str(port), "--temp-dir", temp_dir,
             "--include-dashboard", "false", "--disable-usage-stats", *common],
            env=env, check=True, capture_output=True, timeout=120,
        )  # fmt: skip
        for _ in range(nodes - 1):
            subprocess.run(
                [ray_executable(), "start", "--address", address, *common],
                env=env, check=True, capture_output=True, timeout=120,
            )  # fmt: skip
        yield address, env
    finally:
        stop_processes([temp_dir, f":{port}"])
        shutil.rmtree(temp_dir, ignore_errors=True)
