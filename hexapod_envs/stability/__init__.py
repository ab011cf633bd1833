"""Stability measures for legged robots, pure numpy (no MuJoCo).

All functions take contact points in one frame (metres) and are cheap enough to run every
control step:

- :func:`support_polygon` - convex hull of the contacts, counter-clockwise seen from above.
- :func:`fasm` - Force-Angle Stability Measure (Zhang et al. 2024 eqs. 5-9), degrees;
  :func:`fasm_from_feet` - the same from measured foot forces (minus the support wrench).
- :func:`static_stability_margin` - CoG projection to support polygon boundary, metres.
- :func:`zmp`, :func:`zmp_margin` - force-weighted ZMP and its margin (Coelho et al. 2024 eqs.
32-33).
- :func:`nesm` - Hirose's normalised energy stability margin, metres.
- :func:`fit_plane` - least-squares ground plane z = a x + b y + c (Zhang et al. 2024 §4.2);
  :func:`plane_normal` - only its unit normal, for per-step callers.
"""

from hexapod_envs.stability.fasm import FasmResult, fasm, fasm_from_feet
from hexapod_envs.stability.nesm import nesm, nesm_per_edge
from hexapod_envs.stability.plane_fit import Plane, fit_plane, plane_normal
from hexapod_envs.stability.static_margin import static_stability_margin
from hexapod_envs.stability.support_polygon import support_polygon
from hexapod_envs.stability.zmp import zmp, zmp_margin

__all__ = [
    "FasmResult",
    "Plane",
    "fasm",
    "fasm_from_feet",
    "fit_plane",
    "nesm",
    "nesm_per_edge",
    "plane_normal",
    "static_stability_margin",
    "support_polygon",
    "zmp",
    "zmp_margin",
]
