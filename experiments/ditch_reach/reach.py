"""Does a landing that reaches down until contact let the blind flat-ground gait cross a ditch?

A probe of the per-step structure a pure-PPO ditch policy would need (docs/results.md, "Pure PPO
on the ditch crossing"). The policy plays the flat-ground plan of `HexapodDitchCrossing-v1`'s
reference (blind to the ditch) in joint mode through `agents.upu_gait.UpuGaitPolicy`'s contact
gates, and at each landing gate extends every moving leg whose foot reads no contact by `--rate`
per control step, up to the leg's range, holding the extension until that leg lifts again. With
`--freeze`, a leg that touches is set to its measured extension plus `--preload` instead of
going on with its last command. No planner, no knowledge of the ditch.

    python experiments/ditch_reach/reach.py [--distribution test] [--tasks 10] [--rate 0.02]
        [--freeze --preload 0.002]

Prints one line per task (success, tip-over, steps, CoG advance, largest tilt, the ditch) and
the totals. Findings: README.md.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import hexapod_envs  # noqa: E402,F401
from agents.upu_gait import UpuGaitPolicy  # noqa: E402
from hexapod_envs.checks import count_argument  # noqa: E402
from hexapod_envs.robots.upu.gait_plan import Ditch, plan_flat_past  # noqa: E402
from hexapod_envs.robots.upu.gait_schedule import GaitSchedule  # noqa: E402
from hexapod_envs.robots.upu.params import LEG_NAMES, PLATFORM_LEGS  # noqa: E402

ENV_ID = "HexapodDitchCrossing-v1"
LEG = {leg: i for i, leg in enumerate(LEG_NAMES)}


class ReachingFlatGait(UpuGaitPolicy):
    """The flat-ground plan to the finish line, whose landing legs reach until contact."""

    def __init__(self, env: gym.Env, rate: float, freeze: bool, preload: float):
        self.rate, self.freeze, self.preload = rate, freeze, preload
        super().__init__(env)

    def _ensure_plan(self) -> None:
        if self._planned_for is not None:
            return
        course = self._course()
        _, start_x, width, depth, x0, control_dt = course
        plan = plan_flat_past(self.task.robot, Ditch(start_x, width, depth).end_x, x0)
        self._plan = plan
        self._schedule = GaitSchedule(plan, self.task.robot, control_dt, self.timing)
        self._planned_for = course
        self.tick = 0
        self.reach = np.zeros(6)  # extension added to each leg's command [m]
        self.touched = [False] * 6

    def _action(self, command: np.ndarray) -> np.ndarray:
        command = command.copy()
        command[3:] += self.reach
        return np.clip((command - self._center) / self._half, -1, 1).astype(self._dtype)

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        sched = self.schedule
        obs = self.read(observation)
        contact = obs["foot_contact"] > 0.5
        gate = sched.gate(self.tick)
        if gate is not None and not self._gate_met(gate, contact):
            held = sched.command(self.tick - 1)  # wait at the gate, as the planner's policy does
            if gate.state == "down":  # reach down with the legs not yet on the ground
                top = np.asarray(self.task.joint_high)[3:] - held[3:]
                for i in (LEG[leg] for leg in gate.legs):
                    if contact[i] and self.freeze and self.reach[i] > 0 and not self.touched[i]:
                        self.touched[i] = True
                        self.reach[i] = max(obs["joint_pos"][3 + i] - held[3 + i] + self.preload, 0)
                    elif not contact[i] and not self.touched[i]:
                        self.reach[i] = min(self.reach[i] + self.rate, top[i])
            self.waits += 1
            return self._action(held)
        step, phase = sched.phase(self.tick)
        if phase == "lift":  # the leg leaves the ground: its reach goes with it
            for leg in PLATFORM_LEGS[sched.plan.steps[step].moving]:
                self.reach[LEG[leg]], self.touched[LEG[leg]] = 0.0, False
        action = self._action(sched.command(self.tick))
        self.tick += 1
        return action


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--distribution", choices=("train", "test"), default="test")
    parser.add_argument("--tasks", type=count_argument(), default=10, help="seeds 0..N-1")
    parser.add_argument("--rate", type=float, default=0.02, help="reach per control step [m]")
    parser.add_argument("--freeze", action="store_true", help="hold a touching leg where it is")
    parser.add_argument("--preload", type=float, default=0.002, help="with --freeze [m]")
    args = parser.parse_args(argv)
    env = gym.make(ENV_ID, task_distribution=args.distribution, action_mode="joint")
    policy = ReachingFlatGait(env, args.rate, args.freeze, args.preload)
    successes = tips = 0
    for seed in range(args.tasks):
        obs, info = env.reset(seed=seed)
        policy.reset()
        steps, tilt = 0, 0.0
        while True:
            obs, _, terminated, truncated, info = env.step(policy(obs))
            steps, tilt = steps + 1, max(tilt, info["tilt_deg"])
            if terminated or truncated:
                break
        successes += info["is_success"]
        tips += info["is_tipped_over"]
        task = info["task"]
        print(
            f"task {seed}: success {info['is_success']}, tip-over {info['is_tipped_over']}, "
            f"{steps} steps, advance {info['distance']:.2f} m, largest tilt {tilt:.1f} deg; "
            f"ditch {task['ditch_width']:.2f} m wide, {task['ditch_depth']:.3f} m deep",
            flush=True,
        )
    print(f"{args.distribution}: {successes}/{args.tasks} crossed, {tips} tip-overs")


if __name__ == "__main__":
    main()
