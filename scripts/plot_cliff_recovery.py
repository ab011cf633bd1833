"""Zhang et al. 2024 §5.1 with recovery: the tripod gait alone vs gait + tipping recovery on the
cliff.

Runs HexapodCliffWalk-v0 (default unilateral cliff) from the same seed with
  - the reference tripod gait alone (TripodGaitPolicy; the paper's case, which it could not
    recover),
  - GaitWithRecoveryPolicy in "joint" action mode (full authority over the joint targets),
  - GaitWithRecoveryPolicy in the env's default "residual" mode (residual_scale 0.25: the
    controller's targets are clipped to ±0.25 half-ranges around the still-walking reference),
writes `reports/figures/cliff_walk_recovery.png` (FASM, CoG progress and body tilt over time,
vertical foot forces of the recovery run) and prints a table: tipped or not, minimum FASM once
walking, distance walked, what the controller did.

Run: python scripts/plot_cliff_recovery.py [--out PATH] [--seed N]
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
from agents.tipping.body_model import forces_to_body, quat_to_matrix, tilt_deg  # noqa: E402
from agents.tipping.gait_with_recovery import GaitWithRecoveryPolicy  # noqa: E402
from agents.tipping.judgment import XI_F_DEG  # noqa: E402
from agents.tripod_gait import TripodGaitPolicy  # noqa: E402
from hexapod_envs.robots.heavy_duty import LEG_NAMES  # noqa: E402

RUNS = {
    "gait only": ("residual", TripodGaitPolicy),
    "gait + recovery (joint mode)": ("joint", GaitWithRecoveryPolicy),
    "gait + recovery (residual 0.25)": ("residual", GaitWithRecoveryPolicy),
}
WALK_START = 3.0
"""The gait stands for 3 s before walking (Zhang et al. 2024 §5.1)."""


def rollout(action_mode: str, policy_cls, seed: int) -> dict:
    env = gym.make("HexapodCliffWalk-v0", action_mode=action_mode)
    s = env.unwrapped.observation_structure
    policy = policy_cls(env)
    obs, info = env.reset(seed=seed)
    policy.reset()
    rows = []
    while True:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        rot = quat_to_matrix(obs[s["imu_quat"]])
        fz = forces_to_body(obs[s["foot_force"]], rot)[:, 2]
        rows.append((info["time"], info["fasm_margin_deg"], info["distance"], tilt_deg(rot), fz))
        if terminated or truncated:
            break
    env.close()
    diagnostics = getattr(policy, "diagnostics", None)
    t = np.array([r[0] for r in rows])
    fasm = np.array([r[1] for r in rows])
    return {
        "t": t,
        "fasm": fasm,
        "distance": np.array([r[2] for r in rows]),
        "tilt": np.array([r[3] for r in rows]),
        "fz": np.array([r[4] for r in rows]),
        "tipped": bool(info["is_tipped_over"]),
        "success": bool(info["is_success"]),
        "min_fasm": float(fasm[t > WALK_START].min()),
        "end": float(t[-1]),
        "diagnostics": None if diagnostics is None else dict(diagnostics),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="reports/figures/cliff_walk_recovery.png")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    results = {name: rollout(mode, cls, args.seed) for name, (mode, cls) in RUNS.items()}

    fig, axes = plt.subplots(4, 1, figsize=(10, 12), sharex=True)
    styles = {"gait only": ("0.3", "--"), "gait + recovery (joint mode)": ("C3", "-")}
    styles["gait + recovery (residual 0.25)"] = ("C0", ":")
    main_run = results["gait + recovery (joint mode)"]
    d = main_run["diagnostics"]
    for name, r in results.items():
        color, ls = styles[name]
        label = f"{name}: " + ("tipped over" if r["tipped"] else "stays up")
        axes[0].plot(r["t"], r["fasm"], color=color, ls=ls, lw=1.2, label=label)
        axes[1].plot(r["t"], r["distance"], color=color, ls=ls, lw=1.2, label=name)
        axes[2].plot(r["t"], r["tilt"], color=color, ls=ls, lw=1.2, label=name)
    axes[0].axhline(XI_F_DEG, color="k", ls=":", lw=1, label="ξ_f = 20°")
    for ax in axes[:3]:
        if d["judgment_time"] is not None:
            ax.axvline(d["judgment_time"], color="orange", lw=1)
    axes[0].set_ylabel("FASM [deg]")
    axes[0].set_ylim(-50, 60)
    axes[0].legend(loc="lower left", fontsize=8)
    axes[0].set_title(
        f"Unilateral cliff: tipping judged at {d['judgment_time']:.2f} s (orange); adjustment leg "
        f"{d['adjustment_leg']} -> {d['phase']}"
    )
    axes[1].set_ylabel("CoG progress [m]")
    axes[1].legend(loc="upper left", fontsize=8)
    axes[2].set_ylabel("body tilt [deg]")
    axes[2].set_ylim(0, 25)
    for i, leg in enumerate(LEG_NAMES):
        axes[3].plot(main_run["t"], main_run["fz"][:, i] / 1e3, lw=1, label=leg)
    axes[3].set_ylabel("body-z foot force [kN]\n(recovery, joint mode)")
    axes[3].set_xlabel("time [s]")
    axes[3].legend(loc="upper right", ncol=6, fontsize=8)
    fig.tight_layout()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)

    print(
        f"{'run':34s} {'tipped':>6s} {'min FASM':>9s} {'distance':>9s} {'end [s]':>8s} "
        f"{'success':>7s}  controller"
    )
    for name, r in results.items():
        d = r["diagnostics"]
        what = "-"
        if d is not None and d["judgment_time"] is not None:
            what = (
                f"judged {d['judgment_time']:.2f} s, edge {'-'.join(d['tipping_edge'])}, "
                f"leg {d['adjustment_leg']}, t_s {d['t_s']:.2f} s -> {d['phase']}"
                + (f" ({d['failure']})" if d["failure"] else "")
                + (", targets clipped by the residual range" if d.get("saturated") else "")
            )
        print(
            f"{name:34s} {str(r['tipped']):>6s} {r['min_fasm']:9.1f} "
            f"{r['distance'][-1]:8.2f}m {r['end']:8.1f} {str(r['success']):>7s}  {what}"
        )
    print(f"min FASM is taken after the walk starts ({WALK_START:g} s); figure: {out}")


if __name__ == "__main__":
    main()
