"""Zhang et al. 2024 Fig. 5 for HexapodCliffWalk-v0: CoG position, FASM and vertical foot forces
over time.

Runs the reference tripod gait on flat ground and on the default unilateral cliff and writes
`reports/figures/cliff_walk_fasm.png`. Run: python scripts/plot_cliff_walk.py [--out PATH]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import hexapod_envs  # noqa: E402, F401
from agents.tripod_gait import TripodGaitPolicy  # noqa: E402
from hexapod_envs.envs.heavy_duty import XI_F_DEG  # noqa: E402
from hexapod_envs.robots.heavy_duty import LEG_NAMES  # noqa: E402


def rollout(terrain: str, seed: int = 0, steps: int = 3000) -> dict[str, np.ndarray]:
    env = gym.make("HexapodCliffWalk-v0", terrain=terrain, max_episode_steps=steps)
    force_slice = env.unwrapped.observation_structure["foot_force"]
    policy = TripodGaitPolicy(env)
    obs, info = env.reset(seed=seed)
    rows = []
    while True:
        forces = obs[force_slice].reshape(6, 3)[:, 2]
        rows.append(
            (info["time"], *info["cog"], info["fasm_margin_deg"], info["is_tipping"], *forces)
        )
        obs, _, terminated, truncated, info = env.step(policy(obs))
        if terminated or truncated:
            break
    env.close()
    a = np.array(rows, dtype=float)
    return {
        "t": a[:, 0],
        "cog": a[:, 1:4],
        "fasm": a[:, 4],
        "tipping": a[:, 5].astype(bool),
        "fz": a[:, 6:12],
        "tipped": bool(terminated),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="reports/figures/cliff_walk_fasm.png")
    args = parser.parse_args()
    runs = {"flat ground": rollout("flat", steps=1650), "unilateral cliff": rollout("cliff")}
    fig, axes = plt.subplots(3, 2, figsize=(13, 9), sharex="col")
    for col, (name, r) in enumerate(runs.items()):
        ax = axes[0, col]
        for i, label in enumerate("xyz"):
            ax.plot(r["t"], r["cog"][:, i] - r["cog"][0, i], label=f"CoG {label} - start")
        ax.set_ylabel("CoG displacement [m]")
        ax.set_title(f"{name}: " + ("tipped over" if r["tipped"] else "no tip-over"))
        ax.legend(loc="upper left", fontsize=8)
        ax = axes[1, col]
        ax.plot(r["t"], r["fasm"], color="k", lw=1, label="FASM")
        ax.axhline(XI_F_DEG, color="r", ls="--", lw=1, label="ξ_f = 20°")
        if r["tipping"][150:].any():
            k = 150 + int(np.argmax(r["tipping"][150:]))
            ax.axvline(
                r["t"][k],
                color="orange",
                lw=1,
                label=f"is_tipping first raised ({r['t'][k]:.1f} s)",
            )
        ax.set_ylabel("FASM [deg]")
        ax.set_ylim(-40, 60)
        ax.legend(loc="lower left", fontsize=8)
        ax = axes[2, col]
        for i, leg in enumerate(LEG_NAMES):
            ax.plot(r["t"], r["fz"][:, i] / 1e3, lw=0.8, label=leg)
        ax.set_ylabel("vertical foot force [kN]")
        ax.set_xlabel("time [s]")
        ax.legend(ncol=6, fontsize=7, loc="upper right")
    fig.suptitle("HexapodCliffWalk-v0, reference tripod gait (cf. Zhang et al. 2024 Fig. 5)")
    fig.tight_layout()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    walking = runs["flat ground"]["fasm"][151:]
    print(
        f"flat: FASM while walking {walking.min():.1f}-{walking.max():.1f} deg; "
        f"standing {np.median(runs['flat ground']['fasm'][10:150]):.1f} deg"
    )
    cliff = runs["unilateral cliff"]
    print(
        f"cliff: tipped={cliff['tipped']} at t={cliff['t'][-1]:.1f} s, "
        f"min FASM {cliff['fasm'].min():.1f} deg"
    )
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
