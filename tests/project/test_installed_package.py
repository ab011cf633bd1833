"""The installed package does the main job on its own: a wheel built from this tree, installed
into a fresh venv, runs ``hexapod-evaluate`` from an empty folder with the shipped configs and
models it carries (`agents.run_files.shipped`); plus where relative configs/ and models/ paths
resolve from another folder in this checkout."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.paths import REPO

from agents.run_files.shipped import resolve_shipped, shipped_root


def test_shipped_configs_and_models_resolve_from_another_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert shipped_root() == REPO  # a source checkout reads the repository root
    config = resolve_shipped("configs/evaluate_default.yaml")
    assert config == REPO / "configs" / "evaluate_default.yaml"
    model = resolve_shipped(Path("models", "HexapodIrregularTerrain-v0", "ppo"))
    assert (model / "model.zip").is_file()
    assert resolve_shipped("configs/no_such.yaml") == Path("configs/no_such.yaml")  # as given
    assert resolve_shipped("elsewhere/x.yaml") == Path("elsewhere/x.yaml")
    (tmp_path / "configs").mkdir()
    (tmp_path / "configs" / "evaluate_default.yaml").write_text("title: mine\n")
    mine = resolve_shipped("configs/evaluate_default.yaml")
    assert mine == Path("configs/evaluate_default.yaml")  # the working directory's file wins


def _run(argv, cwd, timeout=600):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["MUJOCO_GL"] = env.get("MUJOCO_GL", "egl")
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


def _source_copy(dest: Path) -> Path:
    """This tree without build outputs, reports and runs (a stale build/ would leak into the
    wheel)."""
    ignore = shutil.ignore_patterns(
        ".git", "build", "dist", "reports", "runs", "*.egg-info", "__pycache__", ".*cache",
        ".venv", "_shipped",
    )  # fmt: skip
    shutil.copytree(REPO, dest, ignore=ignore)
    return dest


@pytest.mark.slow
def test_wheel_installed_in_a_fresh_venv_evaluates_from_an_empty_folder(tmp_path):
    """Offline: the build and the install use this environment's setuptools and dependencies
    (--no-build-isolation, --no-deps, a venv with --system-site-packages); the package itself
    comes from the wheel only."""
    source = _source_copy(tmp_path / "src")
    built = _run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         str(source), "-w", str(tmp_path / "dist")],
        cwd=tmp_path,
    )  # fmt: skip
    assert built.returncode == 0, built.stderr[-3000:]
    (wheel,) = (tmp_path / "dist").glob("hexapod_envs-*.whl")
    venv = tmp_path / "venv"
    made = _run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], tmp_path)
    assert made.returncode == 0, made.stderr[-3000:]
    python, bin_dir = venv / "bin" / "python", venv / "bin"
    installed = _run(
        [str(python), "-m", "pip", "install", "--no-deps", "--no-build-isolation", "-q",
         str(wheel)],
        cwd=tmp_path,
    )  # fmt: skip
    assert installed.returncode == 0, installed.stderr[-3000:]

    empty = tmp_path / "empty"
    empty.mkdir()
    for script in ("hexapod-evaluate", "hexapod-train", "hexapod-export"):
        helped = _run([str(bin_dir / script), "--help"], cwd=empty)
        assert helped.returncode == 0, helped.stderr[-3000:]
        assert helped.stdout.startswith(f"usage: {script}")

    code = (
        "import json, agents, agents.pipeline.cli as cli, agents.run_files.shipped as s;"
        "print(json.dumps([agents.__file__, str(s.shipped_root()), str(cli.DEFAULT_SUITE),"
        " str(s.resolve_shipped('models/HexapodIrregularTerrain-v0/ppo'))]))"
    )
    where = _run([str(python), "-c", code], cwd=empty)
    assert where.returncode == 0, where.stderr[-3000:]
    module, root, suite, model = (Path(p) for p in json.loads(where.stdout))
    site = venv / "lib"
    for path in (module, root, suite, model):
        assert site in path.parents, f"{path} is not the installed copy in {venv}"
    assert suite.is_file() and (model / "model.zip").is_file()
    assert (root / "configs" / "cliff_walk_ppo.yaml").is_file()

    # The default suite (its env kwargs) with a shipped model, on a tiny budget.
    argv = [str(bin_dir / "hexapod-evaluate"), "--envs", "HexapodIrregularTerrain-v0", "--policies",
            "analytical", "ppo:models/{env_id}/ppo", "--episodes", "1",
            "--max-episode-steps", "10", "--no-progress"]  # fmt: skip
    for _ in range(2):  # the second run replaces the default report
        evaluated = _run(argv, cwd=empty)
        assert evaluated.returncode == 0, evaluated.stderr[-3000:]
    report = empty / "reports" / "default"
    metrics = json.loads((report / "metrics.json").read_text())
    runs = metrics["envs"]["HexapodIrregularTerrain-v0"]["policies"]
    assert set(runs) == {"analytical", "ppo:models/{env_id}/ppo"}
    assert str(model / "model.zip") in (report / "report.md").read_text()
