"""A learned gains policy taught by the one-cycle look-ahead (teacher-student distillation).

The look-ahead (`lookahead`, this study) beats the paper's fixed blocks gains by a wide margin
(pitch- and roll-rate medians -20 % and -13 %, 50 % fewer torso-contact steps on the held-out
beds at the 2.5 ms default step; -25 %, -19 % and 87 % at 2 ms), but it needs a copy of the
simulator. PPO on the privileged terrain scan
(``terrain_scan=True``), with ≤ 2 M env steps, did not find those choices: one decision per
gait cycle gives a few thousand noisy rewards. The look-ahead gives more per decision: the
outcome of *every* candidate setting from the same state. Learning from it is the
teacher-student scheme of legged locomotion (a privileged teacher, a student that acts from what
it observes):

1. `demonstrate`: the teacher walks training beds; at every cycle start the student's
   observation is stored with every candidate's outcome (pitch- and roll-rate RMS, contact
   steps, torso footprint clearance) and the teacher's choice is applied.
2. `distill` / `fit_actor`: the actor of an SB3 PPO model (the architecture of the run config,
   the hybrid residual over the paper's gains) is fitted so that its gains minimise the
   outcomes' `CycleCost`, interpolated over the lattice of candidate gains; the observation
   normalisation is the demonstrations'. The result is an ordinary model directory:
   ``evaluate.py``'s ``ppo:<dir>`` runs it like a trained gains agent.

Every simulated control step counts, the teacher's plays included (`Demonstrations.env_steps`),
so the budget compares with a PPO run's env steps. What it achieved on the blocks: README.md
beside this module.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from agents.athena_policy import analytical_policy
from agents.pipeline.envs import EnvSpec

from .lookahead import (
    DEFAULT_COST,
    SCORED,
    CycleCost,
    CycleOutcome,
    Lookahead,
    gain_grid,
    run_episode,
)


@dataclass
class Demonstrations:
    """What the teacher saw and chose, one row per gait cycle."""

    observations: np.ndarray
    """(n, obs_dim) the observation at the cycle start (as the student gets it, unnormalised)."""
    outcomes: np.ndarray
    """(n, k, 4) per candidate, the scored `CycleOutcome` fields: pitch- and roll-rate RMS
    [rad/s], contact steps, smallest torso footprint clearance [m]."""
    candidates: np.ndarray
    """(k, 3) the candidate gains (k_z, k_α, k_β): the lattice ``levels``³, then `reference`
    (unless on the lattice)."""
    levels: np.ndarray
    """(L,) the gain levels of the candidates' lattice."""
    reference: np.ndarray
    """(3,) the analytical controller's gains (the paper's for the terrain): the hybrid's base."""
    beds: np.ndarray
    """(n,) the episode seed of each row (a bed of the task distribution)."""
    env_steps: int
    """Control steps simulated to collect them: the episodes' and the teacher's plays."""

    def costs(self, cost: CycleCost) -> np.ndarray:
        """(n, k) cost of every candidate."""
        return cost.of_rows(self.outcomes)

    @property
    def reference_index(self) -> int:
        """Index of the candidate that is the reference gains."""
        return int(np.argmin(np.abs(self.candidates - self.reference).sum(axis=1)))

    @classmethod
    def concatenate(cls, parts: Sequence[Demonstrations]) -> Demonstrations:
        if not parts:
            raise ValueError("no demonstrations to concatenate")
        first = parts[0]
        if any(not np.array_equal(p.candidates, first.candidates) for p in parts):
            raise ValueError("demonstrations with different candidate sets")
        return cls(
            np.concatenate([p.observations for p in parts]),
            np.concatenate([p.outcomes for p in parts]),
            first.candidates,
            first.levels,
            first.reference,
            np.concatenate([p.beds for p in parts]),
            sum(p.env_steps for p in parts),
        )

    def subset(self, rows: np.ndarray) -> Demonstrations:
        """The given rows (a boolean mask or indices); `env_steps` is kept (what was spent)."""
        return dataclasses.replace(
            self,
            observations=self.observations[rows],
            outcomes=self.outcomes[rows],
            beds=self.beds[rows],
        )

    def save(self, path: str | Path) -> None:
        np.savez_compressed(path, **vars(self))

    @classmethod
    def load(cls, path: str | Path) -> Demonstrations:
        with np.load(path) as data:
            names = [f.name for f in dataclasses.fields(cls)]
            missing = [n for n in names if n not in data]
            if missing:
                raise ValueError(f"{path} is not a demonstrations file (no {', '.join(missing)})")
            fields = {n: data[n] for n in names}
        return cls(**{**fields, "env_steps": int(fields["env_steps"])})


def demonstrate(
    spec: EnvSpec, seed: int, levels: Sequence[float], cost: CycleCost = DEFAULT_COST
) -> Demonstrations:
    """One episode of `spec`'s env (the gains action mode) on the bed of ``seed``, the teacher
    (`Lookahead` over the lattice ``levels``³ and the analytical gains) choosing every
    cycle; returns its rows. The env is built without `spec`'s learner wrappers (hybrid,
    per-cycle decisions, reward terms), which do not change the observation."""
    env = dataclasses.replace(
        spec, hybrid=None, reward_exclude=[], decision="step", cycle_baseline="none"
    ).make()
    try:
        recorder = _Recorder(levels, cost)
        episode = run_episode(env, seed, recorder)
    finally:
        env.close()
    n = len(recorder.observations)
    return Demonstrations(
        np.asarray(recorder.observations, dtype=np.float32).reshape(n, -1),
        np.asarray(recorder.outcomes, dtype=np.float64).reshape(n, -1, SCORED),
        np.asarray(recorder.teacher.candidates, dtype=np.float64),
        np.asarray(levels, dtype=np.float64),
        np.asarray(recorder.reference, dtype=np.float64),
        np.full(n, seed, dtype=np.int64),
        episode["steps"] + recorder.teacher_steps,
    )


class _Recorder:
    """A `run_episode` chooser: the look-ahead's choice, with what it saw and measured kept."""

    def __init__(self, levels: Sequence[float], cost: CycleCost):
        self.levels, self.cost = levels, cost
        self.teacher: Lookahead | None = None
        self.reference: tuple[float, float, float] | None = None
        self.observations: list[np.ndarray] = []
        self.outcomes: list[list[tuple]] = []
        self.teacher_steps = 0

    def __call__(self, env, observation: np.ndarray) -> tuple[float, float, float]:
        if self.teacher is None:  # the terrain's analytical gains, known once it is built
            self.reference = analytical_policy(env).gains
            self.teacher = Lookahead((*gain_grid(self.levels), self.reference), self.cost)
        copies = self.teacher.outcomes(env)  # the exact look-ahead: one copy per candidate
        played: list[CycleOutcome] = [c[0] for c in copies]
        self.observations.append(np.array(observation, dtype=np.float32))
        self.outcomes.append([o[:SCORED] for o in played])
        self.teacher_steps += sum(o.steps for o in played)
        return self.teacher.choose(copies)


def lattice_costs(demos: Demonstrations, cost: CycleCost) -> np.ndarray:
    """(n, L, L, L) cost of the lattice candidates, indexed [k_z, k_α, k_β]."""
    n = len(demos.levels)
    return demos.costs(cost)[:, : n**3].reshape(-1, n, n, n)


def interpolated_cost(lattice, gains, levels: Sequence[float]):
    """Trilinear interpolation of per-row lattice costs (torch (n, L, L, L)) at per-row gains
    (torch (n, 3)), constant beyond the lattice's edges; differentiable in the gains. The levels
    must be evenly spaced."""
    import torch.nn.functional as F

    levels = np.asarray(levels, dtype=np.float64)
    if len(levels) < 2 or not np.allclose(np.diff(levels), levels[1] - levels[0]):
        raise ValueError(f"interpolation needs at least 2 evenly spaced levels, got {levels}")
    lo, hi = float(levels[0]), float(levels[-1])
    coords = (gains.to(lattice.dtype) - lo) / (hi - lo) * 2.0 - 1.0
    # grid_sample's last coordinate indexes the volume's first axis: (k_β, k_α, k_z)
    grid = coords.flip(-1).reshape(-1, 1, 1, 1, 3)
    values = F.grid_sample(
        lattice.unsqueeze(1), grid, mode="bilinear", padding_mode="border", align_corners=True
    )
    return values.reshape(-1)


@dataclass
class FitResult:
    """Mean cycle cost on the validation rows (lattice-interpolated for the student) per epoch,
    and the references on the same rows."""

    history: list[tuple[int, float, float]]
    """(epoch, training mean cost, validation mean cost); epoch 0 is the untrained actor."""
    best_epoch: int
    reference_cost: float
    """The reference gains' measured cost (the paper's, a candidate)."""
    teacher_cost: float
    """The look-ahead's: the cheapest candidate of every row."""
    best_constant_cost: float
    """The lattice point of lowest mean cost over the training rows, on the validation rows."""

    @property
    def best_cost(self) -> float:
        return next(v for e, _, v in self.history if e == self.best_epoch)


def fit_actor(
    policy,
    observations: np.ndarray,
    demos: Demonstrations,
    scale: float,
    validation: np.ndarray,
    cost: CycleCost = DEFAULT_COST,
    epochs: int = 300,
    learning_rate: float = 1e-3,
    batch_size: int = 128,
    seed: int = 0,
    edge_weight: float = 10.0,
) -> FitResult:
    """Fit the actor (mean action) of an SB3 ActorCriticPolicy so that its gains,
    clip(demos.reference + scale x clip(a, -1, 1), 0, 1) as the hybrid residual applies them,
    minimise the teacher-measured cycle cost, interpolated over the lattice, on the training
    rows (``~validation``). Keeps the epoch of lowest validation cost (early stopping).

    Why the cost and not the teacher's choice: a cycle's outcome depends on details of the
    state that the observation does not carry, so the teacher's argmin jumps between distant
    settings in states the student cannot tell apart; regressing on it averages those
    settings. Minimising the interpolated cost averages the costs instead: the student learns
    the setting cheapest on average for what it observes. The teacher measured nothing outside
    the lattice, so gains beyond it cost ``(distance outside)²`` per unit of `edge_weight` (the
    interpolation is flat there: without it the actor drifts to 0 or 1).

    `observations` are what the network sees (normalised). The critic is not touched."""
    import torch

    torch.manual_seed(seed)
    validation = np.asarray(validation, dtype=bool)
    train_rows, held_out = np.flatnonzero(~validation), np.flatnonzero(validation)
    if len(train_rows) == 0 or len(held_out) == 0:
        raise ValueError("fit_actor needs both training and validation rows")
    objective = _GainsObjective(policy, observations, demos, cost, scale, edge_weight)
    history, best_epoch = _train_actor(
        policy, objective, train_rows, held_out, epochs, learning_rate, batch_size, seed
    )
    costs = demos.costs(cost)
    on_lattice = costs[:, : len(demos.levels) ** 3]
    best_constant = int(on_lattice[train_rows].mean(axis=0).argmin())
    return FitResult(
        history,
        best_epoch,
        reference_cost=float(costs[held_out, demos.reference_index].mean()),
        teacher_cost=float(costs[held_out].min(axis=1).mean()),
        best_constant_cost=float(on_lattice[held_out, best_constant].mean()),
    )


class _GainsObjective:
    """What `fit_actor` minimises and reports, on rows of the demonstrations: the gains the
    actor's mean action gives (the hybrid residual over `demos.reference`), their cost
    interpolated over the lattice, and the training loss (that cost plus the penalty for gains
    outside the lattice)."""

    def __init__(self, policy, observations, demos, cost, scale, edge_weight):
        import torch

        device = policy.device
        self.policy, self.scale, self.edge_weight = policy, scale, edge_weight
        self.device = device
        self.obs = torch.as_tensor(observations, dtype=torch.float32, device=device)
        self.levels = demos.levels
        self.lattice = torch.as_tensor(lattice_costs(demos, cost), device=device)
        self.ref = torch.as_tensor(np.asarray(demos.reference, dtype=np.float32), device=device)
        self.lo, self.hi = float(self.levels[0]), float(self.levels[-1])

    def _mean_action(self, rows):
        return self.policy.get_distribution(self.obs[rows]).distribution.mean

    def gains(self, rows):
        """The gains (torch (n, 3)) the hybrid applies: the action clipped to [-1, 1], the
        gains to [0, 1]."""
        return (self.ref + self.scale * self._mean_action(rows).clamp(-1.0, 1.0)).clamp(0.0, 1.0)

    def loss(self, rows):
        """The mean interpolated cost plus `edge_weight` x (distance outside the lattice)²."""
        import torch

        # unclipped, so that the edge term pulls back an action beyond the action space too
        raw = self.ref + self.scale * self._mean_action(rows)
        outside = torch.relu(self.lo - raw) + torch.relu(raw - self.hi)
        cost = interpolated_cost(self.lattice[rows], raw, self.levels)
        return (cost + self.edge_weight * (outside**2).sum(dim=-1)).mean()

    def mean_cost(self, rows) -> float:
        """The mean interpolated cost of the applied gains (no gradient)."""
        import torch

        with torch.no_grad():
            cost = interpolated_cost(self.lattice[rows], self.gains(rows), self.levels)
            return float(cost.mean())


def _train_actor(
    policy,
    objective: _GainsObjective,
    train_rows: np.ndarray,
    held_out: np.ndarray,
    epochs: int,
    learning_rate: float,
    batch_size: int,
    seed: int,
) -> tuple[list[tuple[int, float, float]], int]:
    """Adam on the actor's parameters (its MLP and action net), shuffled mini-batches of the
    training rows each epoch; the policy ends with the weights of the epoch of lowest
    validation cost (early stopping). Returns the history (epoch, training cost, validation
    cost), epoch 0 the untrained actor, and that best epoch."""
    import copy

    import torch

    device = objective.device
    train_t = torch.as_tensor(train_rows, device=device)
    val_rows = torch.as_tensor(held_out, device=device)
    actor = [*policy.mlp_extractor.policy_net.parameters(), *policy.action_net.parameters()]
    optimizer = torch.optim.Adam(actor, lr=learning_rate)
    generator = np.random.default_rng(seed)
    history = [(0, objective.mean_cost(train_t), objective.mean_cost(val_rows))]
    best_state, best_epoch = copy.deepcopy(policy.state_dict()), 0
    for epoch in range(1, epochs + 1):
        for batch in np.array_split(
            generator.permutation(train_rows), max(1, len(train_rows) // batch_size)
        ):
            rows = torch.as_tensor(batch, device=device)
            optimizer.zero_grad()
            objective.loss(rows).backward()
            optimizer.step()
        history.append((epoch, objective.mean_cost(train_t), objective.mean_cost(val_rows)))
        if history[-1][2] < min(v for e, _, v in history[:-1]):
            best_state, best_epoch = copy.deepcopy(policy.state_dict()), epoch
    policy.load_state_dict(best_state)
    return history, best_epoch


CHOICE_MARGINS = (0.0, 0.002, 0.005, 0.01, 0.02, 0.05, np.inf)
"""Predicted cost advantages [rad/s] a `fit_choice` student needs before it leaves its default
setting; chosen on the validation rows (inf: never leave it)."""


@dataclass
class ChoiceResult:
    """Mean measured cycle cost of a `fit_choice` student's choices on the test rows, and the
    baselines on the same rows (single-cycle outcomes from the teacher's states: an offline
    measure, not a closed-loop run of the student)."""

    cost: float
    reference_cost: float
    """The reference gains' (the paper's)."""
    best_constant_cost: float
    """The candidate of lowest mean cost on the training rows: the student's default."""
    oracle_cost: float
    """Every row's cheapest candidate (the teacher's choice when the cost is the teacher's)."""
    margin: float
    """The `CHOICE_MARGINS` entry chosen on the validation rows."""
    departed: float
    """Share of the test rows on which the student chose another setting than its default."""


def fit_choice(
    observations: np.ndarray,
    demos: Demonstrations,
    train: np.ndarray,
    validation: np.ndarray,
    test: np.ndarray,
    cost: CycleCost = DEFAULT_COST,
    epochs: int = 150,
    hidden: int = 256,
    seed: int = 0,
) -> ChoiceResult:
    """Does ``observations`` (n, d) tell which candidate a cycle should get, beyond the best
    fixed setting? A diagnostic student, not a model to ship. Its default is the candidate of
    lowest mean cost on the ``train`` rows (boolean masks); an MLP (two tanh layers of
    ``hidden``) regresses every candidate's measured cost minus the default's on those rows, and
    the student takes the candidate of lowest predicted cost where it predicts an advantage of
    more than a margin, else the default. The epoch and the margin (`CHOICE_MARGINS`) whose
    choices cost least on the ``validation`` rows are kept: with an infinite margin the student
    is the best fixed setting, so it departs from it only where that paid on validation.

    Why the margin: the lowest of many noisy predictions is almost always below zero, so with a
    zero margin a student leaves its default on nearly every cycle. Unlike `fit_actor` it needs
    no interpolation between candidates (which, on a coarse lattice, misprices gains between
    its points, such as the paper's)."""
    import copy

    import torch
    from stable_baselines3.common.torch_layers import create_mlp

    torch.manual_seed(seed)
    train, validation, test = (
        np.flatnonzero(np.asarray(m, dtype=bool)) for m in (train, validation, test)
    )
    if min(len(train), len(validation), len(test)) == 0:
        raise ValueError("fit_choice needs training, validation and test rows")
    costs = demos.costs(cost)
    default = int(costs[train].mean(axis=0).argmin())
    observations = np.asarray(observations, dtype=np.float64)
    mean, std = observations[train].mean(axis=0), observations[train].std(axis=0) + 1e-6
    x = torch.as_tensor((observations - mean) / std, dtype=torch.float32)
    y = torch.as_tensor(costs - costs[:, default : default + 1], dtype=torch.float32)
    net = torch.nn.Sequential(*create_mlp(x.shape[1], y.shape[1], [hidden, hidden], torch.nn.Tanh))
    optimizer = torch.optim.Adam(net.parameters(), lr=1e-3, weight_decay=1e-4)

    def choices(rows: np.ndarray, margin: float) -> np.ndarray:
        with torch.no_grad():
            predicted = net(x[rows]).numpy()
        best = predicted.argmin(axis=1)
        return np.where(predicted[np.arange(len(rows)), best] < -margin, best, default)

    def chosen_cost(rows: np.ndarray, margin: float) -> float:
        return float(costs[rows, choices(rows, margin)].mean())

    def best_margin() -> tuple[float, float]:
        return min((chosen_cost(validation, m), m) for m in CHOICE_MARGINS)

    generator = np.random.default_rng(seed)
    (best_cost, margin), best_state = best_margin(), copy.deepcopy(net.state_dict())
    for _ in range(epochs):
        for batch in np.array_split(generator.permutation(train), max(1, len(train) // 128)):
            optimizer.zero_grad()
            ((net(x[batch]) - y[batch]) ** 2).mean().backward()
            optimizer.step()
        if (found := best_margin())[0] < best_cost:
            (best_cost, margin), best_state = found, copy.deepcopy(net.state_dict())
    net.load_state_dict(best_state)
    return ChoiceResult(
        cost=chosen_cost(test, margin),
        reference_cost=float(costs[test, demos.reference_index].mean()),
        best_constant_cost=float(costs[test, default].mean()),
        oracle_cost=float(costs[test].min(axis=1).mean()),
        margin=margin,
        departed=float(np.mean(choices(test, margin) != default)),
    )


def ground_deviation_features(
    observations: np.ndarray, structure: dict[str, slice], controller
) -> np.ndarray:
    """(n, 3) the posture controller's estimate for the phase each row's cycle starts with:
    torso pitch and roll from the ground plane [rad] (eqs. 24-26,
    `AthenaPostureController.ground_deviation`) and the height error [m], recomputed from the
    row's observation (``structure``: the env's `observation_structure`). The gains scale
    exactly these corrections, so they are the obvious candidate for telling which gains a
    cycle wants. A cycle starts with an even phase, whose stance tripod is ``TRIPODS[1]``.
    The feet are eq. (12) on the observed joint angles; the controller's default start
    ("measured_height") takes its feet's heights from there but their horizontal positions from
    its commands, which the observation lacks: an approximation within the servos' tracking."""
    from hexapod_envs.robots.athena.kinematics import feet_closed_form
    from hexapod_envs.robots.athena.params import LEG_NAMES, TRIPODS

    stance = tuple(LEG_NAMES.index(leg) for leg in TRIPODS[1])
    rows = np.asarray(observations, dtype=np.float64)
    angles = rows[:, structure["joint_pos"]].reshape(-1, 6, 3)
    forces = rows[:, structure["foot_force"]].reshape(-1, 6, 3)
    heights = rows[:, structure["torso_height"]].reshape(-1)
    features = np.zeros((len(rows), 3))
    for k in range(len(rows)):
        feet = feet_closed_form(angles[k], controller.params)
        contact = controller.in_contact(forces[k])
        _, _, d_pitch, d_roll = controller.ground_deviation(feet, contact, stance)
        features[k] = d_pitch, d_roll, controller.height_error(heights[k])
    return features


def held_out_rows(demos: Demonstrations, fraction: float) -> np.ndarray:
    """(n,) True for the rows of the last ``fraction`` of the beds (at least one bed)."""
    beds = np.unique(demos.beds)
    held_out = beds[len(beds) - max(1, round(fraction * len(beds))) :]
    return np.isin(demos.beds, held_out)


def distill(config, demos: Demonstrations, validation: np.ndarray, **fit_kwargs):
    """(model, its VecNormalize or None, `FitResult`, the env's resolved settings): a new PPO
    model of the training config `config` (`agents.run_files.train_config.TrainConfig`, gains
    mode, plain hybrid residual) whose observation statistics are those of the training rows and
    whose actor is fitted by `fit_actor` (``fit_kwargs``)."""
    from agents.pipeline.training import untrained_model
    from agents.run_files.model_files import NormalizationStats

    hybrid = config.hybrid
    if hybrid is None or hybrid.mode != "residual" or hybrid.safety_filter:
        raise ValueError("distilling needs a config whose hybrid section is the plain residual")
    model, settings = untrained_model(config)
    vec_normalize = model.get_vec_normalize_env()
    observations = demos.observations
    if vec_normalize is not None and vec_normalize.norm_obs:
        train_obs = observations[~validation].astype(np.float64)
        vec_normalize.obs_rms.mean = train_obs.mean(axis=0)
        vec_normalize.obs_rms.var = train_obs.var(axis=0)
        vec_normalize.obs_rms.count = float(len(train_obs))
        stats = NormalizationStats.from_vec_normalize(vec_normalize)
        observations = stats.normalize_obs(observations)
    fit_kwargs.setdefault("seed", config.train.seed)
    result = fit_actor(model.policy, observations, demos, hybrid.scale, validation, **fit_kwargs)
    return model, vec_normalize, result, settings
