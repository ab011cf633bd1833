"""SB3 callbacks: episode statistics to TensorBoard, checkpoints, best model with its stats.

TensorBoard tags written besides SB3's own (``rollout/``, ``train/``, ``eval/``, ``time/``):

| tag | meaning (mean over the episodes finished since the last log) |
|---|---|
| ``hexapod/fasm_min_deg``, ``hexapod/fasm_mean_deg`` | per-episode min / mean FASM [deg] |
| ``hexapod/time_below_xi_s`` | per-episode time with FASM below the robot's ξ [s] |
| ``hexapod/success_rate``, ``hexapod/tip_over_rate`` | fraction of episodes |
| ``hexapod/distance_m``, ``hexapod/energy_j`` | when the env reports them |
| ``hexapod/<metric>`` | numeric env-specific episode metrics (see `episode`) |
| ``reward_terms/reward_<term>`` | per-episode sum of each reward term from ``info`` |
| ``eval/fasm_min_deg`` ... | the same FASM/success statistics over EvalCallback's episodes |
| ``eval/success_change_since_start`` | with ``eval.same_tasks``: success rate now - at step 0 |
| ``eval/return_change_since_start`` | with ``eval.same_tasks``: mean return now - at step 0 |
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from stable_baselines3.common.callbacks import BaseCallback, EvalCallback

from ..run_files.artifacts import BEST, checkpoint_dir, save_model_dir
from .episode import EpisodeAccumulator, EpisodeRecord


def record_episode(logger: Any, prefix: str, record: EpisodeRecord) -> None:
    """Add one episode's statistics to the logger's running means under `prefix`/."""
    values = {
        "fasm_min_deg": record.fasm_min_deg,
        "fasm_mean_deg": record.fasm_mean_deg,
        "time_below_xi_s": record.time_below_xi_s,
        "success_rate": None if record.success is None else float(record.success),
        "tip_over_rate": float(record.tipped_over),
        "distance_m": record.distance_m,
        "energy_j": record.energy_j,
    }
    for name, value in record.specifics.items():
        if isinstance(value, int | float) and name not in values:
            values[name] = float(value)
    for name, value in values.items():
        if value is not None:
            logger.record_mean(f"{prefix}/{name}", value)
    if prefix == "hexapod":
        for term, total in record.reward_terms.items():
            logger.record_mean(f"reward_terms/reward_{term}", total)


class EpisodeStatsCallback(BaseCallback):
    """Accumulates every training env's info dicts and logs each finished episode."""

    def __init__(self, new_accumulator: Callable[[], EpisodeAccumulator]):
        super().__init__()
        self.new_accumulator = new_accumulator
        self.accumulators: list[EpisodeAccumulator] = []

    def _on_training_start(self) -> None:
        self.accumulators = [self.new_accumulator() for _ in range(self.training_env.num_envs)]

    def _on_step(self) -> bool:
        infos, dones = self.locals["infos"], self.locals["dones"]
        rewards = self.locals["rewards"]  # VecNormalize-scaled; only the info terms are logged
        for acc, info, done, reward in zip(self.accumulators, infos, dones, rewards, strict=True):
            acc.add(reward, info)
            if done:
                truncated = bool(info.get("TimeLimit.truncated", False))
                record_episode(self.logger, "hexapod", acc.finish(not truncated, truncated))
        return True


class ModelSaver:
    """Saves model directories of one run (model, VecNormalize stats, config, env settings,
    command, meta)."""

    def __init__(
        self, run_dir: Path, config: Any, command: str, env_settings: dict[str, Any] | None = None
    ):
        self.run_dir, self.config, self.command = Path(run_dir), config, command
        self.env_settings = env_settings

    def save(self, model: Any, kind: str, path: Path | None = None, **meta: Any) -> Path:
        if path is None:
            path = checkpoint_dir(self.run_dir, model.num_timesteps)
        vec_normalize = model.get_vec_normalize_env()
        return save_model_dir(
            path, model, vec_normalize, self.config, self.command, kind, meta, self.env_settings
        )


class CriticFirst(BaseCallback):
    """PPO's updates leave the actor (its own feature extractor where the critic has another,
    its network, output layer and log standard deviation) untouched until `steps` env steps
    have been collected: the critic first learns the values of the policy it starts from (a
    warm start's clone), so that the actor's first updates follow advantages of a trained
    critic rather than of a random one."""

    def __init__(self, steps: int):
        super().__init__()
        self.steps = int(steps)

    def _actor(self) -> list[Any]:
        policy = self.model.policy
        shared = policy.share_features_extractor  # then the critic's features too: left
        features = [] if shared else list(policy.pi_features_extractor.parameters())
        return [
            *features,
            *policy.mlp_extractor.policy_net.parameters(),
            *policy.action_net.parameters(),
            policy.log_std,
        ]

    def _set_actor_trainable(self, trainable: bool) -> None:
        for parameter in self._actor():
            parameter.requires_grad_(trainable)

    def _on_training_start(self) -> None:
        self._set_actor_trainable(self.model.num_timesteps >= self.steps)

    def _on_rollout_end(self) -> None:  # the update of this rollout comes next
        if self.model.num_timesteps >= self.steps:
            self._set_actor_trainable(True)

    def _on_training_end(self) -> None:
        self._set_actor_trainable(True)

    def _on_step(self) -> bool:
        return True


class CheckpointEvery(BaseCallback):
    """Saves a checkpoint each time num_timesteps passes a multiple of `freq` (resume-safe)."""

    def __init__(self, freq: int, saver: ModelSaver):
        super().__init__()
        self.freq, self.saver = freq, saver
        self._next = 0

    def _on_training_start(self) -> None:
        self._next = (self.num_timesteps // self.freq + 1) * self.freq

    def _on_step(self) -> bool:
        if self.num_timesteps >= self._next:
            self.saver.save(self.model, "checkpoint")
            self._next = (self.num_timesteps // self.freq + 1) * self.freq
        return True


class SaveBest(BaseCallback):
    """EvalCallback's ``callback_on_new_best``: writes ``best/`` with the eval reward in meta."""

    def __init__(self, saver: ModelSaver):
        super().__init__()
        self.saver = saver

    def _on_step(self) -> bool:
        reward = float(self.parent.best_mean_reward)
        self.saver.save(self.model, "best", self.saver.run_dir / BEST, eval_mean_reward=reward)
        return True


def evaluation_score(successes: Any, results: Any, i: int) -> tuple[float, float]:
    """(success rate, mean return) of evaluation `i` of an EvalCallback log, the key by which
    ``eval.select: success`` keeps ``best/``; success 0 where the log holds none (SB3 logs
    successes only for evaluations whose episodes report ``is_success``)."""
    episodes = successes[i] if i < len(successes) else []
    rate = float(sum(episodes)) / len(episodes) if len(episodes) else 0.0
    return rate, float(sum(results[i]) / len(results[i]))


class StatsEvalCallback(EvalCallback):
    """EvalCallback that also logs FASM/success statistics of its evaluation episodes."""

    def __init__(
        self,
        *args: Any,
        new_accumulator: Callable[[], EpisodeAccumulator],
        task_seed: int | None = None,
        select_saver: ModelSaver | None = None,
        **kwargs: Any,
    ):
        """`new_accumulator`: makes the accumulator of one evaluation episode. `task_seed`:
        reseed the evaluation env with it before every evaluation (the same tasks each time).
        `select_saver`: keep ``best/`` by success rate, then mean return (instead of SB3's mean
        return; pass no ``callback_on_new_best`` then)."""
        super().__init__(*args, **kwargs)
        self.task_seed, self.select_saver = task_seed, select_saver
        self._log_file: str | None = None
        if self.log_path is not None:  # SB3 rewrites its log in place; write a copy, then swap
            self._log_file = self.log_path + ".npz"
            self.log_path = os.path.join(os.path.dirname(self.log_path), ".evaluations.partial")
        self.best_score: tuple[float, float] | None = None
        self._evaluations_handled = 0
        self._make_accumulators = new_accumulator
        self._accumulators: dict[int, EpisodeAccumulator] = {}

    def _on_training_start(self) -> None:
        """Evaluate the initial policy too (step 0 of the learning curve): with a zero-initialised
        action net it is the analytical controller or the reference motion, and ``best/`` then
        only holds a trained policy that scored higher than where training started."""
        super()._on_training_start()
        # SB3 counts calls from this process's start; counting them from the run's start keeps
        # a resumed run's evaluations at the steps of an uninterrupted run's.
        self.n_calls = self.num_timesteps // self.training_env.num_envs
        if self.eval_freq > 0 and self.num_timesteps == 0 and not self.evaluations_timesteps:
            self._on_step()

    def _on_step(self) -> bool:
        self._accumulators = {}
        evaluating = self.eval_freq > 0 and self.n_calls % self.eval_freq == 0
        if evaluating and self.task_seed is not None:
            self.eval_env.seed(self.task_seed)
        self._evaluations_handled = len(self.evaluations_timesteps)
        continue_training = super()._on_step()
        self._after_evaluation()
        return continue_training

    def _on_event(self) -> bool:
        # SB3 runs ``callback_after_eval`` (a sweep's report to Ray Tune, which may stop the
        # trial right there) after writing its log and before returning: our part first.
        self._after_evaluation()
        return super()._on_event()

    def _after_evaluation(self) -> None:
        """Once per new evaluation: move the log SB3 has just written into place, log the change
        since step 0 and keep ``best/`` by the `select_saver` rule."""
        if len(self.evaluations_timesteps) <= self._evaluations_handled:
            return
        self._evaluations_handled = len(self.evaluations_timesteps)
        if self._log_file is not None:
            os.replace(self.log_path + ".npz", self._log_file)
        if self.task_seed is not None:
            self._log_change_since_start()
        if self.select_saver is not None:
            score = self.score(len(self.evaluations_timesteps) - 1)
            if self.best_score is None or score > self.best_score:
                self.best_score = score
                saver = self.select_saver
                saver.save(
                    self.model,
                    "best",
                    saver.run_dir / BEST,
                    eval_mean_reward=score[1],
                    eval_success_rate=score[0],
                )

    def _log_change_since_start(self) -> None:
        """On the same tasks at every evaluation, the paired change of the success rate and the
        mean return of the latest evaluation against the first (step 0 of the run):
        ``eval/success_change_since_start``, ``eval/return_change_since_start``."""
        first, latest = self.score(0), self.score(len(self.evaluations_timesteps) - 1)
        self.logger.record("eval/success_change_since_start", latest[0] - first[0])
        self.logger.record("eval/return_change_since_start", latest[1] - first[1])

    def score(self, i: int) -> tuple[float, float]:
        """(success rate, mean return) of evaluation `i` (`evaluation_score`)."""
        return evaluation_score(self.evaluations_successes, self.evaluations_results, i)

    def _log_success_callback(self, locals_: dict[str, Any], globals_: dict[str, Any]) -> None:
        super()._log_success_callback(locals_, globals_)
        i = locals_["i"]
        acc = self._accumulators.setdefault(i, self._make_accumulators())
        info = locals_["info"]
        acc.add(locals_["reward"], info)
        if locals_["done"]:
            truncated = bool(info.get("TimeLimit.truncated", False))
            record_episode(self.logger, "eval", acc.finish(not truncated, truncated))
