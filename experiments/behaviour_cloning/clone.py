"""Can an MLP actor copy the analytical controller from the sensor observation? (BC + DAgger)

Kick-starting PPO from the reference (issue "agents that learn", item 2) needs an actor that
already acts like the analytical controller. This clones the controller of a ``-v1`` env into
an MLP of the shipped PPO configs' shape (2 x 256 tanh, inputs standardised), in the action mode
in which the controller runs (`agents.registry.ANALYTICAL_ENV_KWARGS`):

1. round 0: the controller drives `episodes` training tasks; every (observation, action) is kept;
2. rounds 1..`rounds` (DAgger, Ross et al. 2011): the clone drives, the controller (stepped on
   every observation, so its gait clock, judgment and plan follow the episode) labels each step;
3. after each round the MLP is fitted on all pairs (Adam, mean squared error, Gaussian noise of
   `noise` standard deviations on the standardised inputs against over-fitting to them);
4. the clone and the controller run the first `tests` benchmark test tasks.

    python experiments/behaviour_cloning/clone.py HexapodCliffWalk-v1
    python experiments/behaviour_cloning/clone.py HexapodStewartTilt-v1 --episodes 8 --rounds 2

Prints the fit per round and one line per test task (success, distance [m], largest tilt [deg],
share of time tipping) for the clone and the controller. Findings: README.md.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np
import torch

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.registry import ANALYTICAL_ENV_KWARGS, analytical_factory
from hexapod_envs import info_keys as keys
from hexapod_envs.checks import count_argument


class Clone:
    """The MLP and the input standardisation of the data it was fitted on."""

    def __init__(self, n_obs: int, n_act: int, seed: int):
        torch.manual_seed(seed)
        layers = [torch.nn.Linear(n_obs, 256), torch.nn.Tanh(), torch.nn.Linear(256, 256)]
        self.net = torch.nn.Sequential(*layers, torch.nn.Tanh(), torch.nn.Linear(256, n_act))
        self.mean, self.std = np.zeros(n_obs), np.ones(n_obs)

    def fit(self, x: np.ndarray, y: np.ndarray, epochs: int, noise: float) -> float:
        """Fit on all pairs; the last epoch's mean squared error (in action units²)."""
        self.mean, self.std = x.mean(axis=0), x.std(axis=0) + 1e-3
        xt = torch.as_tensor((x - self.mean) / self.std, dtype=torch.float32)
        yt = torch.as_tensor(y, dtype=torch.float32)
        optimiser = torch.optim.Adam(self.net.parameters(), lr=1e-3)
        for _ in range(epochs):
            losses = []
            for batch in torch.randperm(len(xt)).split(256):
                inputs = xt[batch] + noise * torch.randn_like(xt[batch])
                loss = ((self.net(inputs) - yt[batch]) ** 2).mean()
                optimiser.zero_grad()
                loss.backward()
                optimiser.step()
                losses.append(loss.item())
        return float(np.mean(losses))

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        z = torch.as_tensor(((observation - self.mean) / self.std)[None], dtype=torch.float32)
        with torch.no_grad():
            return np.clip(self.net(z)[0].numpy(), -1.0, 1.0)


def sensors(obs: np.ndarray, info: dict) -> np.ndarray:
    """The clone's input by default: the sensor observation alone."""
    return obs


def with_ditch_and_time(obs: np.ndarray, info: dict) -> np.ndarray:
    """The sensor observation plus what the ditch planner reads from the task and its clock:
    the ditch's near and far edge ahead of the CoG [m], its depth [m] (5, 5, 0 on flat
    ground) and the episode time [s] / 150 (privileged inputs, from ``info``)."""
    ditch, cog_x = info["ditch"], float(info["cog"][0])
    if ditch is None:
        task = [5.0, 5.0, 0.0]
    else:
        near = ditch["start_x"] - cog_x
        task = [near, near + ditch["width"], ditch["depth"]]
    return np.concatenate([obs, task, [info["time"] / 150.0]])


def episode(
    env, expert, seed: int, clone: Clone | None, pairs: list | None, inputs=sensors, noise=0.0
) -> dict:
    """One episode from ``reset(seed)``: the clone acts (the controller if None, with Gaussian
    action noise of std `noise` from a generator seeded with `seed`); the controller labels
    every step into `pairs` (if given) as (`inputs` (obs, info), action). The last info."""
    obs, info = env.reset(seed=seed)
    expert.reset()
    rng = np.random.default_rng(seed)
    done = False
    while not done:
        label = np.asarray(expert(obs))
        x = inputs(obs, info)
        if pairs is not None:
            pairs.append((x.copy(), np.clip(label, -1.0, 1.0)))
        if clone is not None:
            action = clone(x)
        elif noise:
            action = np.clip(label + noise * rng.normal(size=label.shape), -1.0, 1.0)
        else:
            action = label
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    return info


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("env_id")
    parser.add_argument(
        "--episodes", type=count_argument(), default=8, help="training tasks per round"
    )
    parser.add_argument(
        "--rounds", type=count_argument(0), default=2, help="DAgger rounds after round 0"
    )
    parser.add_argument("--epochs", type=int, default=60)
    parser.add_argument("--noise", type=float, default=0.1)
    parser.add_argument("--tests", type=count_argument(0), default=10, help="benchmark test tasks")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--action-mode", help="the env's action mode (default: the controller's, e.g. joint)"
    )
    parser.add_argument(
        "--task-inputs",
        action="store_true",
        help="HexapodDitchCrossing only: add the ditch's edges and depth and the episode time "
        "to the clone's input (privileged; `with_ditch_and_time`)",
    )
    parser.add_argument(
        "--controller-noise",
        type=float,
        nargs="+",
        metavar="STD",
        help="only run the controller with Gaussian action noise of each STD on `episodes` "
        "training tasks (how precisely a clone must copy it) and stop",
    )
    args = parser.parse_args()
    if args.task_inputs and not args.env_id.startswith("HexapodDitchCrossing"):
        parser.error(f"--task-inputs is for HexapodDitchCrossing ids, not {args.env_id}")
    kwargs = dict(ANALYTICAL_ENV_KWARGS.get(args.env_id, {}))
    if args.action_mode:
        kwargs["action_mode"] = args.action_mode
    inputs = with_ditch_and_time if args.task_inputs else sensors
    make = analytical_factory(args.env_id)
    train = gym.make(args.env_id, task_distribution="train", **kwargs)
    expert = make(train)
    if args.controller_noise:
        for std in args.controller_noise:
            infos = [episode(train, expert, k, None, None, noise=std) for k in range(args.episodes)]
            wins = sum(bool(i[keys.IS_SUCCESS]) for i in infos)
            tips = sum(bool(i[keys.IS_TIPPED_OVER]) for i in infos)
            print(f"action noise std {std}: {wins} successes, {tips} tip-overs of {len(infos)}")
        return
    obs, info = train.reset(seed=0)
    n_inputs = inputs(obs, info).shape[0]
    clone = Clone(n_inputs, train.action_space.shape[0], args.seed)
    pairs: list = []
    start = time.perf_counter()
    for round_ in range(args.rounds + 1):
        for k in range(args.episodes):
            driver = clone if round_ else None
            episode(train, expert, 1000 * round_ + k, driver, pairs, inputs)
        x, y = (np.array(v) for v in zip(*pairs, strict=True))
        loss = clone.fit(x, y, args.epochs, args.noise)
        print(
            f"round {round_}: {len(x)} pairs, fit MSE {loss:.5f}, "
            f"{time.perf_counter() - start:.0f} s",
            flush=True,
        )
    test = gym.make(args.env_id, task_distribution="test", **kwargs)
    test_expert = make(test)  # a controller reads its own env's task (the ditch planner)
    wins = {"clone": 0, "controller": 0}
    for seed in range(args.tests):
        line = [f"task {seed}"]
        for name, actor in (("clone", clone), ("controller", None)):
            info = episode(test, test_expert, seed, actor, None, inputs)
            wins[name] += bool(info[keys.IS_SUCCESS])
            line.append(
                f"{name} {bool(info[keys.IS_SUCCESS])} {info.get('distance', np.nan):.2f} m "
                f"{info[keys.MAX_TILT_DEG]:.1f} deg {info[keys.TIPPING_SHARE]:.2f}"
            )
        print(" | ".join(line), flush=True)
    print(
        f"success on {args.tests} test tasks: clone {wins['clone']}, "
        f"controller {wins['controller']}"
    )


if __name__ == "__main__":
    main()
