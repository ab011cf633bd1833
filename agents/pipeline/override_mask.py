"""PPO that learns nothing from the actions a safety override threw away.

Under a hybrid policy's safety override (`agents.hybrid`: ``mode: safety`` or ``safety_filter``)
the analytical controller acts and the learned action of that step is discarded. Plain PPO
still scores the discarded action with the step's advantage. That advantage does not depend on
the action, so those samples add only variance to the policy gradient (on the cliff walk the
hybrid spends about 30 % of its time below ξ). With ``hybrid.mask_overridden: true`` the
training run records ``info["safety_override"]`` of every step (`RecordOverrides`) and the
rollout buffer (`OverrideMaskedRolloutBuffer`) gives those steps a zero advantage after
normalising the advantages over the other steps; PPO's own per-minibatch normalisation is
turned off, so a zero stays zero. The value function still learns from every step: the returns
are those of GAE, untouched.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stable_baselines3.common.buffers import RolloutBuffer
from stable_baselines3.common.callbacks import BaseCallback


class OverrideMaskedRolloutBuffer(RolloutBuffer):
    """SB3's rollout buffer with a per-step ``overridden`` flag whose steps get no advantage.

    Args (besides RolloutBuffer's):
        normalize: normalise the advantages of the other steps to zero mean and unit std over
            the rollout (what ``ppo.normalize_advantage`` asks; PPO's own is off with this
            buffer, since it would shift the zeros).
    """

    def __init__(self, *args: Any, normalize: bool = True, **kwargs: Any):
        self.normalize = normalize
        super().__init__(*args, **kwargs)

    def reset(self) -> None:
        super().reset()
        self.overridden = np.zeros((self.buffer_size, self.n_envs), dtype=bool)
        """True where the safety override discarded the stored action (set by
        `RecordOverrides` before SB3 adds the step)."""

    def compute_returns_and_advantage(self, last_values: Any, dones: np.ndarray) -> None:
        super().compute_returns_and_advantage(last_values, dones)  # returns use the raw GAE
        kept = ~self.overridden
        advantages = self.advantages
        if self.normalize and kept.any():
            own = advantages[kept]
            advantages[kept] = (own - own.mean()) / (own.std() + 1e-8)
        advantages[~kept] = 0.0


class RecordOverrides(BaseCallback):
    """Writes each env step's ``info["safety_override"]`` into the rollout buffer row that SB3
    is about to add (a callback's ``on_step`` runs after ``env.step`` and before the add)."""

    def _on_step(self) -> bool:
        buffer = self.model.rollout_buffer
        buffer.overridden[buffer.pos] = [
            bool(info.get("safety_override", False)) for info in self.locals["infos"]
        ]
        return True


def masked_ppo_kwargs(normalize_advantage: bool) -> dict[str, Any]:
    """The SB3 PPO keyword arguments that make a model use `OverrideMaskedRolloutBuffer`."""
    return {
        "rollout_buffer_class": OverrideMaskedRolloutBuffer,
        "rollout_buffer_kwargs": {"normalize": normalize_advantage},
        "normalize_advantage": False,
    }
