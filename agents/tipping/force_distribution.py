"""Foot force distribution with a stability-cone constraint, Zhang et al. 2024 §4.3 (eqs. 16-24).

All vectors are in the body frame {C} (x forward, y left, z up); forces in N, lengths in m. The
unknown x ∈ R^{3k} stacks the ground reaction forces on the k stance feet.

Desired wrench (eq. 16). Newton-Euler about the CoG for the supports:
    F_b = m (a_b - g_b),     T_b = I ω̇_b + ω_b × I ω_b,
with a_b the CoG acceleration and g_b gravity, both in the body frame. The printed eq. (16)
(F_b = -m a_b - m R g, T_b = -I ω_b - ω_b × I ω_b) mixes the D'Alembert inertial force with the
support force; the signs above are the ones for which A x = b balances the body.

Tracking (eqs. 17-18). A = [[E ... E], [[P_1]x ... [P_k]x]] with P_i relative to the CoG;
min (Ax - b)ᵀ S (Ax - b) + κ xᵀ W x, i.e. ½ xᵀ U x + fᵀ x with U = 2AᵀSA + 2κW, f = -2AᵀSb.

Force constraints (ref. [37] of the paper): along the terrain normal n, n·f_i >= f_min; the
linearised friction pyramid |t_j·f_i| <= μ n·f_i for the two tangents t_1 (body x projected on
the plane) and t_2 = n × t_1 (pass μ/√2 to inscribe the pyramid in the Coulomb cone).

Stability cone (eqs. 19-24). For support-polygon edge i (unit â_i, counter-clockwise seen from
above, l_i the perpendicular from the CoG to the edge line) the FASM tipping force is
    f*_i = -V_i x,   V_i = (E - â âᵀ)[E ... E] + (1/‖l_i‖) [l̂_i]x â âᵀ [T_1 ... T_k],
with T_j = [P_j]x. Eq. (19)/(20) as printed drop the [l̂]x of eq. (6); it is kept here, so that
f*_i is exactly the force of the FASM (eq. 7) for the support wrench A x. The cone has its apex
at the CoG and as base the circle of radius λ d_min round the support polygon's area centroid G_s
in the terrain plane (d_min: eq. 21). T_1..T_4 are the circle's points along the plane-projected
body +x, +y, -x, -y; tan α_j = ‖r_GGs × r_GTj‖ / |r_GGs · r_GTj| (eq. 22). In the cone frame
(e_1 towards T_1 and e_2 towards T_2, both ⊥ the axis CoG->G_s, e_3 pointing back up the axis) the
inscribed pyramid of eq. (24) is S_Mᵀ (f*_1', f*_2', f*_3') <= 0 with
    S_M = 1/√2 [[√2, 0, -√2, 0], [0, √2, 0, -√2], [tan α_1, tan α_2, tan α_3, tan α_4]]:
f*_1' <= tan α_1/√2 · (-f*_3') etc. For a circular cone that is the pyramid whose corners lie
on the cone (hence the 1/√2). The printed S_Mᵀ V_i x <= 0 contradicts f* = -V_i x (it would
exclude the cone axis itself); the constraint imposed is S_Mᵀ Qᵀ f*_i <= 0, Q = [e_1 e_2 e_3].
When G_s lies straight below the CoG on level ground, Q = E and this is the printed S_M.

Only the totals Σ f and Σ P × f enter f*_i, so the cone limits the wrench the feet may apply,
not how it is shared: when the desired wrench itself violates it (a body already tipping), the
QP trades wrench error for a force set whose tipping forces point into the cone.

The problem is scaled internally (forces divided by a weight scale) so the solver tolerances are
relative. A failed solve is classified with a phase-1 problem (smallest uniform constraint
relaxation): "infeasible" when the relaxation needed is positive, else "solver_error".
"""

from __future__ import annotations

import ctypes
import math
from dataclasses import dataclass, field

import numpy as np
import qpsolvers

try:  # daqp is what qpsolvers calls for solver='daqp'; see _solve_dense
    import daqp
except ImportError:  # pragma: no cover - then qpsolvers reports the missing back end
    daqp = None

from agents.tipping import _compiled
from hexapod_envs.stability import fit_plane, support_polygon
from hexapod_envs.stability._geometry import hull_collinear_message

GRAVITY: float = 9.81
"""[m/s²]."""

SOLVERS: tuple[str, ...] = ("daqp", "quadprog")
"""QP back ends accepted (both dense; daqp is the fast one, quadprog the exact cross-check)."""

CONSTRAINT_BLOCKS: tuple[str, ...] = ("normal", "friction", "stability")

_FEASIBILITY_TOL = 1e-7  # phase-1 relaxation (in units of the force scale) deemed infeasible
_ACCEPT_TOL = 1e-6  # constraint violation (relative to the force scale) accepted as optimal


@dataclass(frozen=True)
class ForceDistributionConfig:
    """Weights and limits of the force-distribution QP (none are given in the paper).

    Attributes:
        wrench_weights: diagonal of S, for (F_x, F_y, F_z, T_x, T_y, T_z); forces in N and
            moments in N·m weigh alike.
        regularization: κ, weight of xᵀWx (W = identity: the smallest forces, no internal
            squeeze); relative to S it sets the wrench-tracking error (~κ/k of b for k feet).
        friction: μ of the friction pyramid (a conservative estimate below the true 0.8).
        min_normal_force: f_min [N] on every stance foot along the terrain normal.
        cone_ratio: λ in (0, 1): base radius of the stability cone as a fraction of d_min.
        stability_cone: impose the cone constraint (eq. 24).
        solver: qpsolvers back end, one of :data:`SOLVERS`.
    """

    wrench_weights: tuple[float, float, float, float, float, float] = (1.0,) * 6
    regularization: float = 1e-3
    friction: float = 0.6
    min_normal_force: float = 500.0
    cone_ratio: float = 0.5
    stability_cone: bool = True
    solver: str = "daqp"

    def __post_init__(self) -> None:
        if len(self.wrench_weights) != 6 or min(self.wrench_weights) <= 0.0:
            raise ValueError(
                f"wrench_weights must be 6 positive numbers, got {self.wrench_weights}"
            )
        if not self.regularization > 0.0:
            raise ValueError(f"regularization (kappa) must be > 0, got {self.regularization}")
        if not self.friction > 0.0:
            raise ValueError(f"friction must be > 0, got {self.friction}")
        if not self.min_normal_force >= 0.0:
            raise ValueError(f"min_normal_force must be >= 0 N, got {self.min_normal_force}")
        if not 0.0 < self.cone_ratio < 1.0:
            raise ValueError(f"cone_ratio (lambda) must lie in (0, 1), got {self.cone_ratio}")
        if self.solver not in SOLVERS:
            raise ValueError(f"unknown solver {self.solver!r}; valid solvers: {SOLVERS}")


def desired_wrench(
    mass: float,
    inertia: np.ndarray,
    gravity_body: np.ndarray,
    accel_body: np.ndarray | None = None,
    omega: np.ndarray | None = None,
    omega_dot: np.ndarray | None = None,
) -> np.ndarray:
    """Desired support wrench b = (F_b, T_b) at the CoG, eq. (16) with Newton-Euler signs.

    Args:
        mass: supported mass [kg].
        inertia: (3, 3) inertia about the CoG in the body frame [kg m²].
        gravity_body: (3,) gravity in the body frame, R_W^C g [m/s²] ((0, 0, -9.81) when level).
        accel_body: (3,) CoG acceleration in the body frame [m/s²] (default 0).
        omega: (3,) body angular velocity [rad/s] (default 0).
        omega_dot: (3,) body angular acceleration [rad/s²] (default 0).

    Returns:
        (6,) [F_b (N), T_b (N m)] that the ground must apply through the feet.
    """
    inertia = np.asarray(inertia, dtype=float)
    if inertia.shape != (3, 3):
        raise ValueError(f"inertia must be a (3, 3) matrix, got shape {inertia.shape}")
    vectors = []
    for name, value in (
        ("gravity_body", gravity_body),
        ("accel_body", accel_body),
        ("omega", omega),
        ("omega_dot", omega_dot),
    ):
        vector = _ZERO3 if value is None else np.asarray(value, dtype=float)
        if vector.shape != (3,):
            raise ValueError(f"{name} must be a (3,) vector, got shape {vector.shape}")
        vectors.append(vector)
    return _compiled.newton_euler_wrench(float(mass), inertia, *vectors)


_ZERO3 = np.zeros(3)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class StabilityCone:
    """Geometry of the stability cone (eqs. 21-22) and its pyramid faces (eq. 24).

    Attributes:
        apex: CoG [m].
        centroid: G_s, area centroid of the support polygon in the terrain plane [m].
        d_min: smallest distance from G_s to a polygon edge line [m] (eq. 21).
        radius: λ d_min [m].
        base_points: (4, 3) T_1..T_4 (towards plane-projected body +x, +y, -x, -y) [m].
        tan_alpha: (4,) tan α_1..α_4 (eq. 22).
        faces: (4, 3) rows c_j with c_j · f* <= 0 inside the pyramid (= S_Mᵀ Qᵀ).
    """

    apex: np.ndarray
    centroid: np.ndarray
    d_min: float
    radius: float
    base_points: np.ndarray
    tan_alpha: np.ndarray
    faces: np.ndarray

    def contains(self, force: np.ndarray, tol: float = 0.0) -> bool:
        """True when the force direction lies in the pyramid (faces · f <= tol ‖f‖)."""
        force = np.asarray(force, dtype=float)
        return bool(np.all(self.faces @ force <= tol * np.linalg.norm(force)))


_NO_NORMAL = np.zeros(3)
"""The placeholder normal of a build that fits the plane through the feet (never written)."""


def stability_cone(
    feet: np.ndarray,
    cog: np.ndarray,
    normal: np.ndarray,
    cone_ratio: float,
    hull: np.ndarray | None = None,
) -> StabilityCone:
    """Build the stability cone of eqs. (21)-(22) for stance ``feet`` (k, 3) and CoG ``cog``.

    The feet are projected onto the plane through their centroid with unit ``normal`` (up);
    ``hull`` (support-polygon vertex indices, counter-clockwise from +normal) is computed when
    not given. Raises ValueError when the CoG is not above that plane.
    """
    feet = np.asarray(feet, dtype=float)
    cog = np.asarray(cog, dtype=float)
    proj, unit_normal = _compiled.project_feet(feet, np.asarray(normal, dtype=float))
    if hull is None:
        hull = support_polygon(proj, up=unit_normal)
    status, values, d_min, radius = _compiled.cone_geometry(
        proj, cog, unit_normal, cone_ratio, np.asarray(hull, dtype=np.int64)
    )
    if status != _compiled.OK:
        raise ValueError(_cog_below(cog, unit_normal))
    return _cone_from(values, d_min, radius, cog)


def _cone_from(values: np.ndarray, d_min: float, radius: float, cog: np.ndarray) -> StabilityCone:
    """The cone kernel's output as a :class:`StabilityCone` (G_s, T_1..T_4, tan α and the
    faces are views of the one array ``values``)."""
    return StabilityCone(
        cog.copy(),
        values[:3],
        d_min,
        radius,
        values[3:15].reshape(4, 3),
        values[15:19],
        values[19:31].reshape(4, 3),
    )


def _cog_below(cog: np.ndarray, normal: np.ndarray) -> str:
    return f"the CoG {cog} is not above the support plane (normal {tuple(normal.tolist())})"


def _cog_on_edge(edge: np.ndarray) -> str:
    return f"the CoG lies on the line of support edge {tuple(edge.tolist())}"


def _moment_rows(rel: np.ndarray) -> np.ndarray:
    """[[P_1]x ... [P_k]x] (3, 3k) for positions ``rel`` (k, 3) relative to the CoG."""
    return _compiled.wrench_map(np.asarray(rel, dtype=float), np.zeros(3))[3:]


def tipping_force_matrices(
    feet: np.ndarray, cog: np.ndarray, edges: np.ndarray, moment_rows: np.ndarray | None = None
) -> np.ndarray:
    """V_i of eq. (20) for every support edge: (m, 3, 3k), with f*_i = -V_i x.

    Args:
        feet: (k, 3) stance feet [m]; cog: (3,) CoG [m].
        edges: (m, 2) support-polygon edges as foot indices, counter-clockwise seen from above.
        moment_rows: optional pre-built [[P_1]x ... [P_k]x] (3, 3k), P_j relative to the CoG.
    """
    feet = np.asarray(feet, dtype=float)
    cog = np.asarray(cog, dtype=float)
    if moment_rows is None:
        moment_rows = _moment_rows(feet - cog)
    moment_rows = np.asarray(moment_rows, dtype=float)
    if moment_rows.shape != (3, 3 * len(feet)):
        raise ValueError(
            f"moment_rows must have shape (3, {3 * len(feet)}) for {len(feet)} feet, "
            f"got {moment_rows.shape}"
        )
    edges = np.asarray(edges, dtype=np.int64)
    status, bad, ima, couple = _compiled.tipping_terms(feet, cog, edges)
    if status != _compiled.OK:
        raise ValueError(_cog_on_edge(edges[bad]))
    return _compiled.tipping_products(ima, couple, moment_rows)


@dataclass(frozen=True)
class ForceQp:
    """One instance of the QP in scaled standard form: min ½ x̃ᵀUx̃ + fᵀx̃ s.t. G x̃ <= h.

    x̃ = x / scale. ``blocks`` maps each constraint group to its rows of G.
    """

    U: np.ndarray
    f: np.ndarray
    G: np.ndarray
    h: np.ndarray
    A: np.ndarray
    b: np.ndarray
    scale: float
    blocks: dict[str, slice]
    edges: np.ndarray
    cone: StabilityCone | None
    normal: np.ndarray


@dataclass(frozen=True)
class ForceDistributionResult:
    """Outcome of one force-distribution solve.

    Attributes:
        status: "optimal", "infeasible" (the constraints admit no force set) or "solver_error"
            (the solver failed on a feasible problem, or the geometry was degenerate).
        forces: (k, 3) ground reaction force on each stance foot, body frame [N]; NaN unless
            status is "optimal".
        wrench: (6,) A x, the wrench the forces apply at the CoG [N, N m].
        wrench_residual: (6,) A x - b.
        slack: per constraint group, h - G x in force units [N] (>= 0 when satisfied):
            "normal" (k,), "friction" (k, 4), "stability" (m, 4) for the m polygon edges.
        max_violation: largest constraint violation [N] (0 when all hold).
        solver: back end used.
        message: detail for non-optimal outcomes.
        cone: the stability cone (None when disabled or not built).
    """

    status: str
    forces: np.ndarray
    wrench: np.ndarray
    wrench_residual: np.ndarray
    slack: dict[str, np.ndarray] = field(repr=False)
    max_violation: float
    solver: str
    message: str = ""
    cone: StabilityCone | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        return self.status == "optimal"


class ForceDistributor:
    """Force-distribution QP for a fixed number of stance feet (Zhang et al. 2024 §4.3).

    Pre-builds what is constant between control steps (the force-sum block [E ... E], the
    weights S and κW, the friction pyramid in the tangent frame); :meth:`build` fills in the
    geometry of one step and :meth:`solve_qp` solves it. :meth:`solve` does both and never raises
    for a well-formed call: infeasibility and solver failures come back as a status.
    """

    def __init__(self, n_feet: int, config: ForceDistributionConfig | None = None) -> None:
        if n_feet < 3:
            raise ValueError(f"force distribution needs at least 3 stance feet, got {n_feet}")
        self.n_feet = k = int(n_feet)
        self.config = cfg = config or ForceDistributionConfig()
        self._s = np.asarray(cfg.wrench_weights, dtype=float)
        self._reg = 2.0 * cfg.regularization * np.eye(3 * k)
        # Friction pyramid rows in the (t1, t2, n) frame: ±t_j - μ n.
        mu = cfg.friction
        self._pyramid = np.array(
            [[1.0, 0.0, -mu], [-1.0, 0.0, -mu], [0.0, 1.0, -mu], [0.0, -1.0, -mu]]
        )
        self._blocks = {"normal": slice(0, k), "friction": slice(k, 5 * k)}
        self._s_col = self._s[:, None]
        self._unit_weights = bool(np.all(self._s == 1.0))
        self._blocks_by_m: dict[int, dict[str, slice]] = {}

    def build(
        self,
        feet: np.ndarray,
        cog: np.ndarray,
        wrench: np.ndarray,
        normal: np.ndarray | None = None,
    ) -> ForceQp:
        """Assemble the QP for stance ``feet`` (k, 3), CoG ``cog`` (3,) and desired ``wrench``.

        ``normal`` is the terrain's unit up-normal in the body frame (default: least-squares
        plane through the feet). Raises ValueError on malformed input or degenerate geometry.

        Runs every control period, so the geometry and the matrices come from one compiled
        kernel (:func:`agents.tipping._compiled.qp_problem`); the returned arrays are fresh.
        """
        k, cfg = self.n_feet, self.config
        feet = np.asarray(feet, dtype=float)
        cog = np.asarray(cog, dtype=float)
        b = np.asarray(wrench, dtype=float)
        if feet.shape != (k, 3):
            raise ValueError(f"feet must have shape ({k}, 3), got {feet.shape}")
        if cog.shape != (3,) or b.shape != (6,):
            raise ValueError(f"cog must be (3,) and wrench (6,), got {cog.shape}, {b.shape}")
        fit_normal = normal is None
        n = _NO_NORMAL if fit_normal else np.asarray(normal, dtype=float)
        if n.shape != (3,):
            raise ValueError(f"normal must be a (3,) vector, got shape {n.shape}")
        status, bad, n, a_mat, hull, edges, values, d_min, radius, scale, u_mat, f_vec, g, h = (
            _compiled.qp_problem(
                feet,
                cog,
                b,
                n,
                fit_normal,
                cfg.cone_ratio,
                cfg.stability_cone,
                self._s_col,
                self._unit_weights,
                self._reg,
                self._pyramid,
                cfg.min_normal_force,
            )
        )
        if status == _compiled.NOT_FINITE:
            # The kernel's check is a finite sum (NaN and ±inf propagate): finite entries fail
            # it only when their sum overflows.
            if np.isfinite(feet).all() and np.isfinite(cog).all() and np.isfinite(b).all():
                raise ValueError("feet, cog and wrench are too large: their sum overflows")
            raise ValueError("feet, cog and wrench must be finite")
        if status == _compiled.NO_PLANE:
            fit_plane(feet)  # raises the ValueError that names the problem
        if status == _compiled.HULL_COLLINEAR:
            raise ValueError(hull_collinear_message(k))
        if status == _compiled.COG_NOT_ABOVE:
            raise ValueError(_cog_below(cog, n))
        if status == _compiled.COG_ON_EDGE:
            raise ValueError(_cog_on_edge(edges[bad]))
        return ForceQp(
            U=u_mat,
            f=f_vec,
            G=g,
            h=h,
            A=a_mat,
            b=b,
            scale=scale,
            blocks=self._blocks_for(len(hull)),
            edges=edges,
            cone=_cone_from(values, d_min, radius, cog) if cfg.stability_cone else None,
            normal=n,
        )

    def _blocks_for(self, m: int) -> dict[str, slice]:
        """Rows of G per constraint group for an m-gon support polygon (a fresh dict)."""
        blocks = self._blocks_by_m.get(m)
        if blocks is None:
            blocks = self._blocks_by_m[m] = dict(self._blocks)
            if self.config.stability_cone:
                k = self.n_feet
                blocks["stability"] = slice(5 * k, 5 * k + 4 * m)
        return dict(blocks)

    def solve_qp(self, qp: ForceQp, solver: str | None = None) -> ForceDistributionResult:
        """Solve a built QP with ``solver`` (default: the config's). Never raises on failure."""
        solver = solver or self.config.solver
        if solver not in SOLVERS:
            raise ValueError(f"unknown solver {solver!r}; valid solvers: {SOLVERS}")
        try:
            x_scaled = _solve_dense(qp.U, qp.f, qp.G, qp.h, solver)
        except Exception as error:  # noqa: BLE001 - a solver crash must not stop the control loop
            return self._failure(qp, solver, "solver_error", f"{type(error).__name__}: {error}")
        if x_scaled is None:
            relax = _phase_one(qp, solver)
            if relax is None:
                return self._failure(qp, solver, "solver_error", "solver and phase-1 both failed")
            if relax > _FEASIBILITY_TOL:
                return self._failure(
                    qp,
                    solver,
                    "infeasible",
                    f"constraints need a relaxation of {relax * qp.scale:.4g} N to be satisfiable",
                )
            return self._failure(qp, solver, "solver_error", "solver failed on a feasible problem")
        slack_all, violation, x, wrench, residual = _compiled.qp_outcome(
            qp.G, qp.h, x_scaled, qp.scale, qp.A, qp.b
        )
        status, message = "optimal", ""
        if violation > _ACCEPT_TOL * qp.scale:
            status, message = "solver_error", f"solution violates constraints by {violation:.4g} N"
        return ForceDistributionResult(
            status=status,
            forces=x.reshape(self.n_feet, 3) if status == "optimal" else self._nan_forces(),
            wrench=wrench,
            wrench_residual=residual,
            slack=self._split(slack_all, qp),
            max_violation=violation,
            solver=solver,
            message=message,
            cone=qp.cone,
        )

    def solve(
        self,
        feet: np.ndarray,
        cog: np.ndarray,
        wrench: np.ndarray,
        normal: np.ndarray | None = None,
        solver: str | None = None,
    ) -> ForceDistributionResult:
        """Build and solve (see :meth:`build`); degenerate geometry gives "solver_error"."""
        try:
            qp = self.build(feet, cog, wrench, normal)
        except ValueError as error:
            if np.shape(feet) != (self.n_feet, 3) or np.shape(wrench) != (6,):
                raise
            nan6 = np.full(6, np.nan)
            return ForceDistributionResult(
                status="solver_error",
                forces=self._nan_forces(),
                wrench=nan6,
                wrench_residual=nan6,
                slack={},
                max_violation=math.nan,
                solver=solver or self.config.solver,
                message=f"degenerate geometry: {error}",
            )
        return self.solve_qp(qp, solver)

    def _nan_forces(self) -> np.ndarray:
        return np.full((self.n_feet, 3), np.nan)

    def _split(self, slack: np.ndarray, qp: ForceQp) -> dict[str, np.ndarray]:
        out = {}
        for name, rows in qp.blocks.items():
            part = slack[rows]
            out[name] = part if name == "normal" else part.reshape(-1, 4)
        return out

    def _failure(self, qp: ForceQp, solver: str, status: str, message: str):
        nan6 = np.full(6, np.nan)
        return ForceDistributionResult(
            status=status,
            forces=self._nan_forces(),
            wrench=nan6,
            wrench_residual=nan6,
            slack=self._split(np.full_like(qp.h, np.nan), qp),
            max_violation=math.nan,
            solver=solver,
            message=message,
            cone=qp.cone,
        )


_DAQP_BOUNDS: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # rows -> (lower bounds, sense)


def _solve_dense(p_mat, q_vec, g_mat, h_vec, solver: str) -> np.ndarray | None:
    """argmin ½ xᵀPx + qᵀx s.t. Gx <= h with ``solver``; None when it finds no solution.

    For daqp this is the very call qpsolvers.solve_qp makes (qpsolvers' daqp_solve_problem for
    a dense problem with inequalities only: lower bounds -1e30, sense 0), minus its problem
    checks and Solution bookkeeping, which cost more than the solve itself (about 8 of 14 µs
    for the 4-foot problem); the solution is the same to the bit. Other back ends go through
    qpsolvers.
    """
    if solver != "daqp" or daqp is None:
        return qpsolvers.solve_qp(p_mat, q_vec, g_mat, h_vec, solver=solver)
    rows = len(h_vec)
    bounds = _DAQP_BOUNDS.get(rows)
    if bounds is None:
        bounds = _DAQP_BOUNDS[rows] = (np.full(rows, -1e30), np.zeros(rows, dtype=ctypes.c_int))
    x, _, exitflag, _ = daqp.solve(p_mat, q_vec, g_mat, h_vec, *bounds, primal_start=None)
    return x if exitflag > 0 else None


def _phase_one(qp: ForceQp, solver: str) -> float | None:
    """Smallest uniform relaxation s >= 0 with G x̃ <= h + s (scaled units); None on failure.

    Solved as min ½ s² + ½ ε ‖x̃‖² s.t. G x̃ - s <= h, which is always feasible.
    """
    n = qp.U.shape[0]
    eps = 1e-9
    p_mat = np.diag(np.concatenate([np.full(n, eps), [1.0]]))
    q_vec = np.zeros(n + 1)
    g_mat = np.hstack([qp.G, -np.ones((len(qp.h), 1))])
    try:
        z = qpsolvers.solve_qp(p_mat, q_vec, g_mat, qp.h, solver=solver)
    except Exception:  # noqa: BLE001
        return None
    if z is None:
        return None
    return max(0.0, float(z[-1]))
