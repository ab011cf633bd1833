"""A trained model's step-0 policy, rebuilt from the model itself (or, for a warm-started run,
the run's ``warm_start/`` model: the clone of its teacher, before PPO).

A run whose config zeroes the actor's last layer at the start (``policy.zero_init_action_net``,
or the ``hybrid`` / ``knobs`` sections' key of that name) starts with a deterministic action of
exactly 0 whatever the observation: the reference motion (residual PPO), the analytical
controller (a hybrid) or the knobs' neutral setting. The same model with that layer zeroed
again therefore acts exactly like step 0, and an evaluation of both on the same tasks tells
whether training improved on its start (`scripts/check_step0.py`).

Only the weights of ``action_net`` change; the rest of the network, the normalisation statistics
and the config are the model's own (they do not reach a zero layer's output). The weights are
read with ``torch.load(weights_only=True)``: nothing is unpickled.
"""

from __future__ import annotations

import io
import json
import shutil
import zipfile
from pathlib import Path

from .artifacts import META_FILE, MODEL_FILE, WARM_START, find_model, is_complete, read_meta
from .errors import UserError
from .model_files import atomic_path
from .train_config import load_train_config

POLICY_WEIGHTS = "policy.pth"
"""The entry of an SB3 ``model.zip`` that holds the policy's state dict."""
ACTION_NET = ("action_net.weight", "action_net.bias")
"""The actor's last layer: its output is the action's mean."""
STEP0_KIND = "step0"
"""``meta.json`` kind of a rebuilt step-0 model."""


def write_step0_model(model_path: str | Path, out_dir: str | Path) -> Path:
    """Write `model_path`'s step-0 policy as a model directory at `out_dir` (replaced if it
    exists) and return it: a warm-started run's ``warm_start/`` model, or the model with its
    zero-initialised output layer zeroed again. UserError when the model's run did neither:
    its step 0 was a random network that the model no longer holds."""
    files = find_model(model_path)
    if files.model.name != MODEL_FILE:
        raise UserError(
            f"{files.model}: give the model's directory (its {MODEL_FILE}) to rebuild its step 0"
        )
    config = files.training_config()
    train_config = None if config is None else load_train_config(data=config)
    if train_config is not None and train_config.warm_start is not None:
        return _copy_model_dir(_warm_start_dir(files.directory), Path(out_dir))
    if train_config is None or not train_config.starts_at_zero_action:
        raise UserError(
            f"the model at {files.model} was not trained from a zero-initialised actor "
            "(zero_init_action_net in its config.yaml), so its step-0 policy cannot be rebuilt"
        )
    out_dir = _copy_model_dir(files.directory, Path(out_dir))
    _zero_action_net(out_dir / MODEL_FILE)
    meta = {**read_meta(files.directory), "kind": STEP0_KIND, "num_timesteps": 0}
    meta["rebuilt_from"] = str(files.model)
    for key in [k for k in meta if k.startswith("eval_")]:
        del meta[key]  # the trained model's evaluation, not this policy's
    (out_dir / META_FILE).write_text(json.dumps(meta, indent=2) + "\n")
    return out_dir


def _copy_model_dir(source: Path, out_dir: Path) -> Path:
    """`source` copied to `out_dir` (replaced if it exists)."""
    if out_dir.exists():
        shutil.rmtree(out_dir)
    shutil.copytree(source, out_dir)
    return out_dir


def _warm_start_dir(model_dir: Path) -> Path:
    """A warm-started run's step 0 is its ``warm_start/`` model (the clone, before PPO), beside
    the model directory (``best/``, ``final/``) or above its checkpoints folder."""
    for run_dir in (model_dir.parent, model_dir.parent.parent):
        if is_complete(run_dir / WARM_START):
            return run_dir / WARM_START
    raise UserError(
        f"the model at {model_dir} was warm-started, and its step 0 is the run's "
        f"{WARM_START}/ model, which is not beside it; give the model inside its run directory"
    )


def _zero_action_net(model_zip: Path) -> None:
    import torch

    with zipfile.ZipFile(model_zip) as archive:
        entries = {info.filename: archive.read(info) for info in archive.infolist()}
    if POLICY_WEIGHTS not in entries:
        raise UserError(f"{model_zip} holds no {POLICY_WEIGHTS}: not an SB3 model file")
    state = torch.load(io.BytesIO(entries[POLICY_WEIGHTS]), weights_only=True)
    missing = [key for key in ACTION_NET if key not in state]
    if missing:
        raise UserError(f"{model_zip} has no actor output layer ({', '.join(missing)})")
    for key in ACTION_NET:
        state[key] = torch.zeros_like(state[key])
    buffer = io.BytesIO()
    torch.save(state, buffer)
    entries[POLICY_WEIGHTS] = buffer.getvalue()
    with atomic_path(model_zip) as tmp, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as out:
        for name, data in entries.items():
            out.writestr(name, data)
