"""Normalised benchmark scores: 0 = random actions, 100 = the analytical controller.

As D4RL normalises returns between a random and an expert policy, a policy's score on an env is
``100 x (success - success_random) / (success_analytical - success_random)`` with the success
rates measured on the same tasks (the reference rates are held fixed, as D4RL's are). Across
envs the aggregate is the interquartile mean (IQM) of the per-env scores, with a 95 %
stratified-bootstrap interval from rliable (Agarwal et al. 2021, "Deep RL at the edge of the
statistical precipice"): every episode's success (0 or 1) is normalised with its env's scale,
giving an (episodes x envs) matrix per policy; the bootstrap resamples episodes within each env,
and the statistic is the IQM over envs of each env's mean (its normalised success rate).

An env on which the analytical controller does not beat random actions has no scale: it is left
out of the scores (and the report says so).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

RANDOM, ANALYTICAL = "random", "analytical"


def env_scale(success: Mapping[str, float]) -> tuple[float, float] | None:
    """(random, analytical) success rates of one env, or None without a usable scale."""
    if RANDOM not in success or ANALYTICAL not in success:
        return None
    low, high = float(success[RANDOM]), float(success[ANALYTICAL])
    return (low, high) if high > low else None


def normalised(rate: float, scale: tuple[float, float]) -> float:
    """100 x (rate - random) / (analytical - random)."""
    low, high = scale
    return 100.0 * (rate - low) / (high - low)


def env_scales(
    successes: Mapping[str, Mapping[str, list[bool]]],
) -> dict[str, tuple[float, float]]:
    """``{env: (random, analytical) success rates}`` of the envs with a usable scale.
    `successes` is ``{env: {policy: [success per episode]}}``."""
    scales = {
        env: env_scale({p: float(np.mean(v)) for p, v in by_policy.items()})
        for env, by_policy in successes.items()
    }
    return {env: scale for env, scale in scales.items() if scale is not None}


def env_scores(
    successes: Mapping[str, Mapping[str, list[bool]]],
) -> dict[str, dict[str, float]]:
    """``{policy: {env: normalised success rate}}`` for every policy on every env with a scale
    on which it ran, including policies that did not run on every env (which get no IQM)."""
    out: dict[str, dict[str, float]] = {}
    for env, scale in env_scales(successes).items():
        for policy, episodes in successes[env].items():
            out.setdefault(policy, {})[env] = normalised(float(np.mean(episodes)), scale)
    return dict(sorted(out.items()))


def score_matrices(
    successes: Mapping[str, Mapping[str, list[bool]]],
) -> tuple[dict[str, np.ndarray], list[str]]:
    """``{policy: (episodes x envs) normalised per-episode scores}`` over the envs with a scale
    on which the policy ran the same number of episodes as every other; and those envs.
    `successes` is ``{env: {policy: [success per episode]}}``."""
    scales = env_scales(successes)
    envs = list(scales)
    out = {}
    for policy in sorted({p for env in envs for p in successes[env]}):
        if not all(policy in successes[env] for env in envs):
            continue
        columns = [
            [normalised(float(x), scales[env]) for x in successes[env][policy]] for env in envs
        ]
        if len({len(c) for c in columns}) == 1:
            out[policy] = np.array(columns, dtype=float).T
    return out, envs


def iqm_intervals(
    matrices: Mapping[str, np.ndarray], reps: int = 2000, seed: int = 0
) -> dict[str, tuple[float, float, float]]:
    """``{policy: (IQM, CI low, CI high)}`` of the score matrices (rliable, 95 % stratified
    bootstrap over episodes). ImportError naming the extra if rliable is not installed."""
    try:
        from rliable import library as rly
        from rliable import metrics
    except ImportError as error:  # pragma: no cover - rliable ships with the [sweep] extra
        raise ImportError(
            "the aggregate benchmark score needs rliable: pip install 'hexapod_envs[sweep]'"
        ) from error

    def iqm(scores: np.ndarray) -> np.ndarray:  # (episodes x envs) -> IQM of the env means
        return np.array([metrics.aggregate_iqm(scores.mean(axis=0, keepdims=True))])

    # rliable 1.2 draws through NumPy's global generator: seed it for reproducible intervals.
    np.random.seed(seed)  # noqa: NPY002
    points, intervals = rly.get_interval_estimates(dict(matrices), iqm, reps=reps)
    return {p: (float(points[p][0]), *map(float, intervals[p][:, 0])) for p in matrices}
