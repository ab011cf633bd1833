"""Li et al. 2018 Fig. 9: workspace of the 3-UPU mechanism by the limit-boundary search (§4.2).

Writes the xz, yz and xy projections and a 3-D view of the boundary points, coloured by the
limit that bounds them (limb length -> top/bottom surfaces, Hooke joints -> side surfaces), with
the eq. (20) step path on the xz projection. Run:
    python scripts/plot_upu_workspace.py [--out reports/figures/upu_workspace.png] [--step 0.005]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from hexapod_envs.robots.upu.gait_plan import case_study_path  # noqa: E402
from hexapod_envs.robots.upu.params import UpuParams  # noqa: E402
from hexapod_envs.robots.upu.workspace import search_workspace  # noqa: E402

COLOURS = {
    "limb_min": "tab:blue",
    "limb_max": "tab:red",
    "hooke_theta1": "tab:green",
    "hooke_theta2": "tab:orange",
}
MM = 1000.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("reports/figures/upu_workspace.png"))
    parser.add_argument("--step", type=float, default=0.005, help="search grid spacing [m]")
    args = parser.parse_args()

    params = UpuParams()
    ws = search_workspace(params, step=args.step)
    pts = ws.boundary_points * MM
    labels = ws.boundary_limit
    path = case_study_path(params).sample(41) * MM

    fig = plt.figure(figsize=(12, 9))
    panels = [
        (fig.add_subplot(2, 2, 1), 0, 2, "(a) xz projection"),
        (fig.add_subplot(2, 2, 2), 1, 2, "(b) yz projection"),
        (fig.add_subplot(2, 2, 3), 0, 1, "(c) xy projection"),
    ]
    for ax, i, j, title in panels:
        for name, colour in COLOURS.items():
            sel = labels == name
            ax.scatter(pts[sel, i], pts[sel, j], s=1, c=colour, alpha=0.25, label=name)
        ax.set_xlabel(f"{'xyz'[i]} [mm]")
        ax.set_ylabel(f"{'xyz'[j]} [mm]")
        ax.set_title(title)
        ax.set_aspect("equal")
    panels[0][0].plot(path[:, 0], path[:, 1], "k-", lw=2, label="eq. (20) step path")
    panels[0][0].legend(loc="lower left", fontsize=7, markerscale=6)
    ax3 = fig.add_subplot(2, 2, 4, projection="3d")
    every = max(1, len(pts) // 6000)
    for name, colour in COLOURS.items():
        sel = np.flatnonzero(labels == name)[::every]
        ax3.scatter(pts[sel, 0], pts[sel, 1], pts[sel, 2], s=1, c=colour, alpha=0.3)
    ax3.set_xlabel("x [mm]")
    ax3.set_ylabel("y [mm]")
    ax3.set_zlabel("z [mm]")
    ax3.set_title("(d) 3-D workspace boundary")
    ext = ws.extent()
    fig.suptitle(
        "3-UPU workspace (r = 125, R = 160 mm, l in [365, 465] mm, Hooke angles within ±45°)\n"
        f"x {ext['x'][0] * MM:.0f}..{ext['x'][1] * MM:.0f}, "
        f"y {ext['y'][0] * MM:.0f}..{ext['y'][1] * MM:.0f}, "
        f"z {ext['z'][0] * MM:.0f}..{ext['z'][1] * MM:.0f} mm, "
        f"volume {ws.volume * 1e3:.1f} L"
    )
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}  (extent {ext}, volume {ws.volume:.5f} m^3)")


if __name__ == "__main__":
    main()
