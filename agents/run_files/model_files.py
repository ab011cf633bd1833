"""Model files that cannot run code when loaded, written so that a crash never half-writes one.

Why: a pickle runs arbitrary code when it is loaded, and researchers load each other's models.
Two files of a saved model used pickles:

- ``vecnormalize.pkl`` (SB3's ``VecNormalize.save``). The statistics are now saved as plain
  arrays in ``vecnormalize.npz`` (`NormalizationStats`) and read with ``allow_pickle=False``.
- SB3's ``model.zip`` stores some entries of its ``data`` JSON as base64 cloudpickle (spaces,
  the policy class, schedules, the last observation, episode buffers). `load_ppo` lists those
  entries *before* SB3 sees the file and replaces every one of them with an object rebuilt from
  the run's config and the env (SB3's ``custom_objects``), so nothing is unpickled; the weights
  are read by SB3 with ``torch.load(weights_only=True)``. A file with an entry we cannot rebuild
  is refused, naming the entry.

Old files (a ``vecnormalize.pkl``, or a zip with unknown pickled entries) load only with the
explicit opt-in ``--trust-pickle``, for files whose source the user trusts.

Every file is written atomically (a temporary file in the same directory, then ``os.replace``),
so a crash or a second Ctrl-C leaves either the old file or the new one, never a torn one.
"""

from __future__ import annotations

import contextlib
import json
import os
import pickle
import tempfile
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from .errors import UserError

TRUST_PICKLE_FLAG = "--trust-pickle"

STATS_FILE = "vecnormalize.npz"
LEGACY_STATS_FILE = "vecnormalize.pkl"

_REBUILT_ENTRIES = (
    "policy_class",
    "policy_kwargs",
    "observation_space",
    "action_space",
    "learning_rate",
    "lr_schedule",
    "clip_range",
    "clip_range_vf",
    "rollout_buffer_class",
    "rollout_buffer_kwargs",
    "_last_obs",
    "_last_episode_starts",
    "_last_original_obs",
    "ep_info_buffer",
    "ep_success_buffer",
)
"""The pickled entries of an SB3 PPO ``model.zip`` that `load_ppo` knows how to rebuild. The
last five are training-time state that SB3 recreates (reset env, fresh buffers) when it is None."""


# --- atomic writes -------------------------------------------------------------------------
@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside `path` to write to; on success it replaces `path` in one rename
    (on failure it is removed and `path` is untouched)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)


# --- normalisation statistics --------------------------------------------------------------
@dataclass(frozen=True)
class NormalizationStats:
    """SB3 VecNormalize's running statistics as plain arrays (a Box observation space)."""

    obs_mean: np.ndarray
    obs_var: np.ndarray
    obs_count: float
    ret_mean: float
    ret_var: float
    ret_count: float
    clip_obs: float
    clip_reward: float
    epsilon: float
    gamma: float
    norm_obs: bool
    norm_reward: bool

    @classmethod
    def from_vec_normalize(cls, vec_normalize: Any) -> NormalizationStats:
        obs_rms, ret_rms = vec_normalize.obs_rms, vec_normalize.ret_rms
        if isinstance(obs_rms, dict):
            raise UserError("normalisation statistics of Dict observation spaces are not supported")
        return cls(
            obs_mean=np.asarray(obs_rms.mean, dtype=np.float64),
            obs_var=np.asarray(obs_rms.var, dtype=np.float64),
            obs_count=float(obs_rms.count),
            ret_mean=float(ret_rms.mean),
            ret_var=float(ret_rms.var),
            ret_count=float(ret_rms.count),
            clip_obs=float(vec_normalize.clip_obs),
            clip_reward=float(vec_normalize.clip_reward),
            epsilon=float(vec_normalize.epsilon),
            gamma=float(vec_normalize.gamma),
            norm_obs=bool(vec_normalize.norm_obs),
            norm_reward=bool(vec_normalize.norm_reward),
        )

    def apply_to(self, vec_normalize: Any) -> None:
        """Load these statistics into a freshly built VecNormalize (to resume training)."""
        if vec_normalize.obs_rms.mean.shape != self.obs_mean.shape:
            raise UserError(
                f"normalisation statistics have observation shape {self.obs_mean.shape}, the "
                f"env has {vec_normalize.obs_rms.mean.shape}"
            )
        vec_normalize.obs_rms.mean = self.obs_mean.copy()
        vec_normalize.obs_rms.var = self.obs_var.copy()
        vec_normalize.obs_rms.count = self.obs_count
        vec_normalize.ret_rms.mean = np.float64(self.ret_mean)
        vec_normalize.ret_rms.var = np.float64(self.ret_var)
        vec_normalize.ret_rms.count = self.ret_count
        vec_normalize.clip_obs, vec_normalize.clip_reward = self.clip_obs, self.clip_reward
        vec_normalize.epsilon, vec_normalize.gamma = self.epsilon, self.gamma
        vec_normalize.norm_obs, vec_normalize.norm_reward = self.norm_obs, self.norm_reward

    def normalize_obs(self, observation: np.ndarray) -> np.ndarray:
        """What the network saw in training: VecNormalize's clipped z-score (frozen statistics)."""
        if not self.norm_obs:
            return observation
        z = (observation - self.obs_mean) / np.sqrt(self.obs_var + self.epsilon)
        return np.clip(z, -self.clip_obs, self.clip_obs).astype(np.float32)

    def save(self, path: str | Path) -> None:
        arrays = {f.name: np.asarray(getattr(self, f.name)) for f in fields(self)}
        with atomic_path(path) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, **arrays)

    @classmethod
    def load(cls, path: str | Path) -> NormalizationStats:
        """Read a ``.npz`` written by `save`; UserError naming the file if it is damaged."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as data:
                values = {f.name: data[f.name] for f in fields(cls)}
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
            raise UserError(
                f"the normalisation statistics {path} are unreadable or incomplete ({exc}); "
                "the file is damaged: use another checkpoint or retrain"
            ) from None
        stats = cls(
            obs_mean=values["obs_mean"].astype(np.float64),
            obs_var=values["obs_var"].astype(np.float64),
            **{k: float(values[k]) for k in ("obs_count", "ret_mean", "ret_var", "ret_count")},
            **{k: float(values[k]) for k in ("clip_obs", "clip_reward", "epsilon", "gamma")},
            norm_obs=bool(values["norm_obs"]),
            norm_reward=bool(values["norm_reward"]),
        )
        numbers = [stats.obs_mean, stats.obs_var, stats.obs_count, stats.epsilon, stats.clip_obs]
        if stats.obs_mean.shape != stats.obs_var.shape or not all(
            np.all(np.isfinite(x)) for x in numbers
        ):
            raise UserError(
                f"the normalisation statistics {path} hold non-finite or mismatched "
                "arrays; the file is damaged"
            )
        return stats


def load_stats(
    model_dir: str | Path, trust_pickle: bool = False, required: bool = False
) -> NormalizationStats | None:
    """The statistics of a model directory: ``vecnormalize.npz``, else (only when trusted) the
    legacy ``vecnormalize.pkl``; None when the model was trained without normalisation.
    `required` (its config normalises): a missing file is a UserError, not a policy that would
    act on observations on a scale it never saw."""
    model_dir = Path(model_dir)
    if (model_dir / STATS_FILE).is_file():
        return NormalizationStats.load(model_dir / STATS_FILE)
    legacy = model_dir / LEGACY_STATS_FILE
    if not legacy.is_file():
        if required:
            raise UserError(
                f"{model_dir} has no {STATS_FILE}, but its config.yaml normalises (the normalize "
                "section): without the statistics the policy would act on inputs on a scale it "
                "never saw, and training would restart them. Copy the file from the model's run"
            )
        return None
    if not trust_pickle:
        raise UserError(
            f"{legacy} is a pickle file, which can run code when it is loaded; refusing it. "
            f"If you trust its source, pass {TRUST_PICKLE_FLAG} (the statistics are then "
            f"converted to {STATS_FILE} on the next save)"
        )
    try:
        with open(legacy, "rb") as fh:
            vec_normalize = pickle.load(fh)  # the user opted in with --trust-pickle
    except Exception as exc:  # a damaged pickle can raise nearly anything
        raise UserError(f"cannot read the normalisation statistics {legacy}: {exc!r}") from None
    if not hasattr(vec_normalize, "obs_rms") or not hasattr(vec_normalize, "ret_rms"):
        raise UserError(
            f"{legacy} holds a {type(vec_normalize).__name__}, not SB3 VecNormalize statistics"
        )
    return NormalizationStats.from_vec_normalize(vec_normalize)


# --- SB3 model zips ------------------------------------------------------------------------
def pickled_entries(model_zip: str | Path) -> list[str]:
    """Names of the ``data`` entries that SB3 would unpickle; UserError if the zip is damaged."""
    model_zip = Path(model_zip)
    try:
        with zipfile.ZipFile(model_zip) as archive:
            data = json.loads(archive.read("data"))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile) as exc:
        raise UserError(
            f"the model file {model_zip} is damaged or not an SB3 model ({exc})"
        ) from None
    if not isinstance(data, dict):
        raise UserError(f"the model file {model_zip} is not an SB3 model (its data is no mapping)")
    return sorted(k for k, v in data.items() if isinstance(v, dict) and ":serialized:" in v)


def policy_class(privileged_critic: bool = False, score_read_actions_only: bool = False) -> Any:
    """The SB3 policy class of a run: ``MlpPolicy``, or with ``policy.critic_privileged`` the
    asymmetric `agents.privileged_critic_policy.PrivilegedCriticPolicy`; with
    ``policy.score_read_actions_only`` their forms of `agents.read_actions` (the same weights)."""
    if score_read_actions_only:
        from ..read_actions import ReadActionsMlpPolicy, ReadActionsPrivilegedPolicy

        return ReadActionsPrivilegedPolicy if privileged_critic else ReadActionsMlpPolicy
    if privileged_critic:
        from ..privileged_critic_policy import PrivilegedCriticPolicy

        return PrivilegedCriticPolicy
    from stable_baselines3 import PPO

    return PPO.policy_aliases["MlpPolicy"]


def ppo_custom_objects(
    policy_kwargs: dict[str, Any],
    observation_space: Any,
    action_space: Any,
    learning_rate: Any = 0.0,
    clip_range: Any = 0.0,
    clip_range_vf: Any = None,
    privileged_critic: bool = False,
    score_read_actions_only: bool = False,
) -> dict[str, Any]:
    """Objects that replace every pickled entry of a PPO zip (see `_REBUILT_ENTRIES`).

    Inference needs no schedules (0.0); resuming passes the config's learning-rate and clip
    schedules. The policy class is the one `training` trains (`policy_class`)."""
    return {
        "policy_class": policy_class(privileged_critic, score_read_actions_only),
        "policy_kwargs": dict(policy_kwargs),
        "observation_space": observation_space,
        "action_space": action_space,
        "learning_rate": learning_rate,
        "lr_schedule": None,  # rebuilt from learning_rate by SB3's _setup_model
        "clip_range": clip_range,
        "clip_range_vf": clip_range_vf,
        "rollout_buffer_class": None,  # SB3 picks RolloutBuffer for a Box space
        "rollout_buffer_kwargs": {},
        "_last_obs": None,  # None: SB3 resets the env before the next rollout
        "_last_episode_starts": None,
        "_last_original_obs": None,
        "ep_info_buffer": None,  # None: SB3 starts fresh episode-statistics buffers
        "ep_success_buffer": None,
    }


def load_ppo(
    model_zip: str | Path,
    custom_objects: dict[str, Any],
    trust_pickle: bool = False,
    **load_kwargs: Any,
) -> Any:
    """``PPO.load`` that unpickles nothing unless `trust_pickle`; clear UserErrors otherwise."""
    from stable_baselines3 import PPO

    model_zip = Path(model_zip)
    unknown = [k for k in pickled_entries(model_zip) if k not in custom_objects]
    if unknown and not trust_pickle:
        raise UserError(
            f"the model file {model_zip} holds pickled entries {unknown} that cannot be rebuilt "
            f"without running code from the file; refusing it. If you trust its source, pass "
            f"{TRUST_PICKLE_FLAG}"
        )
    try:
        return PPO.load(model_zip, custom_objects=custom_objects, **load_kwargs)
    except Exception as exc:  # damaged weights raise pickle, zip, torch or shape errors
        text = str(exc).strip()
        if isinstance(exc, pickle.UnpicklingError) or "weights only" in text.lower():
            text = "the weights are not plain tensors"  # torch's advice here is the unsafe one
        first = text.splitlines()[0] if text else type(exc).__name__
        raise UserError(
            f"cannot load the PPO model {model_zip}: its weights or data are damaged or do not "
            f"match this env ({type(exc).__name__}: {first[:200]})"
        ) from None
