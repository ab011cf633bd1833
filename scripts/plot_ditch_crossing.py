"""Li et al. 2018 Figs. 9, 12, 13, 14: the 3-UPU hexapod's 3-3 gait on flat ground and across a
ditch.

Runs `agents.upu_gait.UpuGaitPolicy` on HexapodDitchCrossing-v0 and writes to
reports/figures/ (default):

- ditch_margin_flat.png (Fig. 12): static stability margin d over time, walking on flat ground;
- ditch_margin_crossing.png (Fig. 14): the same while crossing the ditch (default: the paper's,
  140 mm deep x 350 mm wide);
- ditch_crossing_side.png (Fig. 13): side view of the crossing, terrain, platform-centre paths
  and the footholds of both platforms;
- ditch_workspace.png (Fig. 9): workspace projections, by scripts/plot_upu_workspace.py;
- ditch_margins.json: the figures' numbers (minimum margins, steps, distance).

The margin plotted is the env's ``static_margin_m``: the distance from the CoG projection (the
model's CoG from the known masses) to the nearest side of the polygon of the feet in contact,
measured every control step. The planned margin of the kinematic model (`margin_profile`
minimum) is drawn as a reference line. Run:
    python scripts/plot_ditch_crossing.py [--out-dir reports/figures] [--width 0.35 --depth 0.14]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import gymnasium as gym  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import hexapod_envs  # noqa: E402, F401
from agents.upu_gait import UpuGaitPolicy  # noqa: E402
from hexapod_envs.robots.upu.params import LEG_NAMES, UPPER_LEGS  # noqa: E402

MM = 1000.0


def run(seed: int = 0, **kwargs) -> dict:
    """One episode of the gait policy; per-step time series and the footholds."""
    env = gym.make("HexapodDitchCrossing-v0", action_mode="joint", **kwargs)
    policy = UpuGaitPolicy(env)
    obs, info = env.reset(seed=seed)
    policy.reset()
    base = env.unwrapped
    rows = {"t": [], "margin": [], "n_contacts": [], "tilt": [], "upper": [], "lower": []}
    footholds = []
    was_down = np.ones(6, dtype=bool)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        done = terminated or truncated
        feet = base.data.xpos[base._foot_body].copy()
        down = np.array([leg in info["stance_legs"] for leg in LEG_NAMES])
        for i in np.flatnonzero(down & ~was_down):
            footholds.append((LEG_NAMES[i], feet[i, 0], feet[i, 2]))
        was_down = down
        rows["t"].append(info["time"])
        rows["margin"].append(info["static_margin_m"])
        rows["n_contacts"].append(len(info["stance_legs"]))
        rows["tilt"].append(info["tilt_deg"])
        rows["upper"].append(base.data.body("upper").xpos.copy())
        rows["lower"].append(base.data.body("torso").xpos.copy())
    out = {k: np.array(v) for k, v in rows.items()}
    out.update(
        footholds=footholds,
        info=info,
        plan=policy.plan,
        status=policy.status,
        ditch=base.ditch if base.terrain == "ditch" else None,
    )
    env.close()
    return out


def plot_margin(result: dict, title: str, path: Path) -> None:
    t, d = result["t"], result["margin"] * MM
    fig, ax = plt.subplots(figsize=(10, 3.8))
    six = result["n_contacts"] == 6
    ax.fill_between(t, 0, d.max() * 1.05, where=six, color="0.9", step="mid", label="six legs")
    ax.plot(t, d, lw=1.2, color="tab:blue", label="measured d (feet in contact)")
    planned = result["plan"].min_margin * MM
    ax.axhline(planned, color="tab:red", ls="--", lw=1, label=f"planned minimum {planned:.1f} mm")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("static stability margin d [mm]")
    ax.set_ylim(min(0.0, d.min()) - 5, d.max() * 1.05)
    ax.set_xlim(t[0], t[-1])
    ax.set_title(f"{title}: min d = {d.min():.1f} mm over {len(t)} control steps")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_side(result: dict, path: Path) -> None:
    ditch = result["ditch"]
    fig, ax = plt.subplots(figsize=(11, 4.5))
    x = np.linspace(-0.4, 1.8, 2000)
    ground = np.array([-ditch.depth if ditch.start_x < v < ditch.end_x else 0.0 for v in x])
    ax.fill_between(x * MM, ground * MM, -250, color="0.75", step="mid")
    ax.plot(x * MM, ground * MM, "k-", lw=1)
    upper, lower = result["upper"], result["lower"]
    ax.plot(upper[:, 0] * MM, upper[:, 2] * MM, color="tab:blue", lw=1.5, label="upper centre")
    ax.plot(lower[:, 0] * MM, lower[:, 2] * MM, color="tab:orange", lw=1.5, label="lower centre")
    for label, legs, colour in (
        ("upper feet", UPPER_LEGS, "tab:blue"),
        ("lower feet", tuple(leg for leg in LEG_NAMES if leg not in UPPER_LEGS), "tab:orange"),
    ):
        pts = np.array([(fx, fz) for leg, fx, fz in result["footholds"] if leg in legs])
        if len(pts):
            ax.scatter(pts[:, 0] * MM, pts[:, 1] * MM, s=18, color=colour, marker="v", label=label)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("z [mm]")
    ax.set_ylim(-250, 750)
    ax.set_title(
        f"Crossing a {ditch.depth * MM:.0f} mm deep x {ditch.width * MM:.0f} mm wide ditch: "
        f"{len(result['plan'].steps)} platform steps (strides "
        f"{result['plan'].strides.min() * MM:.0f}-{result['plan'].strides.max() * MM:.0f} mm)"
    )
    ax.legend(loc="center left", fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=ROOT / "reports" / "figures")
    parser.add_argument("--width", type=float, default=0.35, help="ditch width [m]")
    parser.add_argument("--depth", type=float, default=0.14, help="ditch depth [m]")
    parser.add_argument("--skip-workspace", action="store_true", help="do not redraw Fig. 9")
    args = parser.parse_args()
    args.out_dir.mkdir(parents=True, exist_ok=True)

    flat = run(terrain="flat")
    crossing = run(ditch_width=args.width, ditch_depth=args.depth)
    for name, result in (("flat", flat), ("crossing", crossing)):
        if result["status"] != "ok" or not result["info"]["is_success"]:
            raise SystemExit(f"{name}: the gait did not finish ({result['status']})")
    plot_margin(
        flat, "Walking on flat ground (cf. Fig. 12)", args.out_dir / "ditch_margin_flat.png"
    )
    plot_margin(
        crossing,
        f"Crossing a {args.depth * MM:.0f} x {args.width * MM:.0f} mm ditch (cf. Fig. 14)",
        args.out_dir / "ditch_margin_crossing.png",
    )
    plot_side(crossing, args.out_dir / "ditch_crossing_side.png")
    summary = {
        name: {
            "min_margin_m": float(r["margin"].min()),
            "planned_min_margin_m": float(r["plan"].min_margin),
            "control_steps": len(r["t"]),
            "platform_steps": len(r["plan"].steps),
            "strides_m": [round(float(s), 4) for s in r["plan"].strides],
            "distance_m": float(r["info"]["distance"]),
            "max_tilt_deg": float(r["tilt"].max()),
            "success": bool(r["info"]["is_success"]),
        }
        for name, r in (("flat", flat), ("crossing", crossing))
    }
    (args.out_dir / "ditch_margins.json").write_text(json.dumps(summary, indent=2))
    print(json.dumps(summary, indent=1))
    if not args.skip_workspace:
        subprocess.run(
            [
                sys.executable,
                str(ROOT / "scripts" / "plot_upu_workspace.py"),
                "--out",
                str(args.out_dir / "ditch_workspace.png"),
            ],
            check=True,
        )
    print(f"wrote figures to {args.out_dir}")


if __name__ == "__main__":
    main()
