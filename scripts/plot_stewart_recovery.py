"""Zhang et al. 2024 Fig. 6 for HexapodStewartTilt-v0: tipping recovery on the tilting Stewart
platform.

For each of the six cases (climb / descend / side x stance LF-LR-RM / LM-RF-RR) runs the robot
twice from the same seed: held on its tripod (zero residual) and with TippingRecoveryPolicy.
Writes one figure per case, `reports/figures/stewart_<scenario>_<stance>.png`, with
  - the FASM over time (controller and held robot, ξ_f, judgment and landing, platform tilt),
  - the tipping edge (the support-polygon edge attaining the FASM) over time,
  - the vertical (body-z) foot forces with the controller, and the QP's planned forces after
    landing (dashed),
and prints a table beside the paper's numbers (§5.2).

Run: python scripts/plot_stewart_recovery.py [--out-dir DIR] [--reach-model kinematic|paper]
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
from agents.tipping.body_model import forces_to_body, quat_to_matrix  # noqa: E402
from agents.tipping.controller import TippingRecoveryPolicy  # noqa: E402
from agents.tipping.judgment import XI_F_DEG  # noqa: E402
from hexapod_envs.robots.heavy_duty import LEG_NAMES  # noqa: E402

CASES = [(s, st) for st in ("LF-LR-RM", "LM-RF-RR") for s in ("climb", "descend", "side")]

PAPER = {  # Zhang et al. 2024 §5.2: adjustment leg, adjustment time t_s [s], foothold [mm], FASM
    # after
    ("climb", "LF-LR-RM"): ("RR", 0.74, (-2390, -1908, -1741), "≈40"),
    ("descend", "LF-LR-RM"): ("RF", 1.0, (2490, -1908, -1741), "≈45"),
    ("side", "LF-LR-RM"): ("LM", 2.1, (0, 1894, -1783), "≈21.5"),
    ("climb", "LM-RF-RR"): ("LR", 2.31, (-2390, 1908, -1741), "(≈40)"),
    ("descend", "LM-RF-RR"): ("LF", 1.3, (2490, 1913, -1728), "(≈45)"),
    ("side", "LM-RF-RR"): ("RM", 1.48, (0, -1894, -1782), "(≈21.5)"),
}
"""The paper gives 'after' margins for the first stance only; (..) marks the second stance."""

LEG_COLORS = dict(zip(LEG_NAMES, plt.cm.tab10.colors[:6], strict=True))


def run(
    scenario: str,
    stance: str,
    controlled: bool,
    seed: int,
    env_kwargs: dict | None = None,
    **policy_kwargs,
) -> dict:
    """One episode; per-step time series, the controller's final diagnostics, and the stability
    cone's λ and the QP's status of every supported-phase step (``cone_ratios``: NaN solved
    without the cone, None no QP that step; ``qp_status``).

    `env_kwargs` go to the env (e.g. tilt_rate_deg, max_tilt_deg), `policy_kwargs` to
    TippingRecoveryPolicy."""
    env = gym.make("HexapodStewartTilt-v0", scenario=scenario, stance=stance, **(env_kwargs or {}))
    s = env.unwrapped.observation_structure
    policy = TippingRecoveryPolicy(env, **policy_kwargs) if controlled else None
    obs, info = env.reset(seed=seed)
    if policy is not None:
        policy.reset()
    rows, planned, cone, qp_status = [], [], [], []
    while True:
        action = policy(obs) if policy is not None else np.zeros(18)
        obs, _, terminated, truncated, info = env.step(action)
        rot = quat_to_matrix(obs[s["imu_quat"]])
        fz = forces_to_body(obs[s["foot_force"]], rot)[:, 2]
        edge = "-".join(info["fasm_edge"]) if info["fasm_edge"] else "none"
        rows.append((info["time"], info["fasm_margin_deg"], info["platform_tilt_deg"], edge, fz))
        if policy is not None and policy.diagnostics["phase"] == "supported":
            cone.append(policy.diagnostics["qp_cone_ratio"])
            qp_status.append(policy.diagnostics["qp_status"])
        if policy is not None and policy.diagnostics["planned_forces"] is not None:
            d = policy.diagnostics
            plan = dict(zip(d["qp_legs"], d["planned_forces"][:, 2], strict=True))
            planned.append((info["time"], [plan.get(leg, np.nan) for leg in LEG_NAMES]))
        if terminated or truncated:
            break
    env.close()
    return {
        "t": np.array([r[0] for r in rows]),
        "fasm": np.array([r[1] for r in rows]),
        "tilt": np.array([r[2] for r in rows]),
        "edge": [r[3] for r in rows],
        "fz": np.array([r[4] for r in rows]),
        "planned_t": np.array([p[0] for p in planned]),
        "planned": np.array([p[1] for p in planned]).reshape(-1, 6),
        "tipped": bool(info["is_tipped_over"]),
        "end_time": float(info["time"]),
        "diagnostics": dict(policy.diagnostics) if policy is not None else None,
        "cone_ratios": cone,
        "qp_status": qp_status,
        "env_adjustment_leg": info.get("adjustment_leg"),
    }


def fasm_at(run_: dict, t: float) -> float:
    k = int(np.searchsorted(run_["t"], t))
    return float(run_["fasm"][min(k, len(run_["fasm"]) - 1)])


def plot_case(scenario: str, stance: str, ctrl: dict, held: dict, out: Path) -> None:
    d = ctrl["diagnostics"]
    fig, axes = plt.subplots(3, 1, figsize=(10, 10), sharex=True)
    ax = axes[0]
    ax.plot(ctrl["t"], ctrl["fasm"], color="C3", lw=1.5, label="FASM, recovery controller")
    held_label = "FASM, tripod held" + (" (tipped over)" if held["tipped"] else "")
    ax.plot(held["t"], held["fasm"], color="0.4", lw=1, ls="--", label=held_label)
    ax.axhline(XI_F_DEG, color="k", ls=":", lw=1, label="ξ_f = 20°")
    if d["judgment_time"] is not None:
        ax.axvline(
            d["judgment_time"], color="orange", lw=1, label=f"judged ({d['judgment_time']:.2f} s)"
        )
    if d["landing_time"] is not None:
        ax.axvline(
            d["landing_time"],
            color="green",
            lw=1,
            label=f"{d['adjustment_leg']} landed ({d['landing_time']:.2f} s)",
        )
    ax.set_ylabel("FASM [deg]")
    ax.set_ylim(-5, 60)
    twin = ax.twinx()
    twin.plot(ctrl["t"], ctrl["tilt"], color="C0", lw=0.8, alpha=0.6)
    twin.set_ylabel("platform tilt [deg]", color="C0")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(
        f"Stewart platform, {scenario}, stance {stance}: adjustment leg {d['adjustment_leg']} "
        f"(paper: {PAPER[(scenario, stance)][0]}), "
        + ("tipped over" if ctrl["tipped"] else "no tip-over")
    )

    ax = axes[1]
    names = sorted(set(ctrl["edge"]) | set(held["edge"]))
    code = {name: i for i, name in enumerate(names)}
    ax.step(
        ctrl["t"], [code[e] for e in ctrl["edge"]], where="post", color="C3", label="controller"
    )
    ax.step(
        held["t"], [code[e] for e in held["edge"]], where="post", color="0.4", ls="--", label="held"
    )
    ax.set_yticks(range(len(names)), names)
    ax.set_ylabel("tipping edge")
    ax.legend(loc="upper right", fontsize=8)

    ax = axes[2]
    for i, leg in enumerate(LEG_NAMES):
        ax.plot(ctrl["t"], ctrl["fz"][:, i] / 1e3, color=LEG_COLORS[leg], lw=1, label=leg)
        if len(ctrl["planned_t"]):
            ax.plot(
                ctrl["planned_t"], ctrl["planned"][:, i] / 1e3, color=LEG_COLORS[leg], lw=1, ls="--"
            )
    ax.set_ylabel("body-z foot force [kN]\n(dashed: QP plan)")
    ax.set_xlabel("time [s]")
    ax.legend(loc="upper right", ncol=6, fontsize=8)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", default="reports/figures")
    parser.add_argument("--reach-model", default="kinematic", choices=("kinematic", "paper"))
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    header = (
        f"{'case':22s} {'leg':>9s} {'t_s [s] [forecast]':>18s} {'recovery':>8s} "
        f"{'FASM before':>11s} "
        f"{'FASM after':>13s} {'min after':>9s} {'held':>7s} {'ctrl':>7s}  "
        "foothold [mm] ours | paper"
    )
    print(
        f"reach model: {args.reach_model}; FASM after = 0.5 s after landing; paper value in (); "
        "[forecast] = eq. 15's time to S = 0 before ϰ and the clamp"
    )
    print(header)
    for scenario, stance in CASES:
        ctrl = run(scenario, stance, True, args.seed, reach_model=args.reach_model)
        held = run(scenario, stance, False, args.seed)
        d = ctrl["diagnostics"]
        p_leg, p_ts, p_foot, p_after = PAPER[(scenario, stance)]
        name = f"stewart_{scenario}_{stance}.png"
        plot_case(scenario, stance, ctrl, held, Path(args.out_dir) / name)
        landed = d["landing_time"]
        after = fasm_at(ctrl, landed + 0.5) if landed is not None else float("nan")
        min_after = float(ctrl["fasm"][ctrl["t"] >= landed].min()) if landed else float("nan")
        foot = (
            "none"
            if d["foothold"] is None
            else "(" + ", ".join(f"{1000 * v:.0f}" for v in d["foothold"]) + ")"
        )
        print(
            f"{scenario + ' ' + stance:22s} {d['adjustment_leg'] or '-':>3s} ({p_leg}) "
            f"{d['t_s'] or float('nan'):4.2f} ({p_ts:4.2f}) "
            f"[{d['time_to_zero_s'] or float('nan'):4.1f}] "
            f"{d['recovery_time'] or float('nan'):8.2f} "
            f"{d['fasm_before_landing_deg'] or float('nan'):11.1f} "
            f"{after:6.1f} ({p_after:>5s}) {min_after:9.1f} "
            f"{'tipped' if held['tipped'] else 'up':>7s} {'tipped' if ctrl['tipped'] else 'up':>7s}"
            f"  {foot} | {p_foot}"
        )
    print(f"figures: {args.out_dir}/stewart_<scenario>_<stance>.png")


if __name__ == "__main__":
    main()
