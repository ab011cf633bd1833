"""Rows of the reproduction report: each headline number of the three papers beside ours.

Every row is a dict with `id`, `paper`, `quantity`, `paper_value`, `value`, `unit`,
`tolerance` (human phrase), `holds` (bool) and `setting` (how it was measured). Every value is
simulated when the report is made, by the measurement code of the study scripts and tests
(experiments.athena_posture.study, scripts/plot_stewart_recovery.py,
scripts/plot_cliff_recovery.py); `quick` keeps the closed-form rows (Table II, 3-UPU limb length
and IK). The calibration findings behind the rows' settings are in README.md beside this file.
"""

from __future__ import annotations

import functools
import math
from collections import Counter
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from hexapod_envs.envs.irregular_terrain import CALIBRATED_MODEL

ROOT = Path(__file__).resolve().parents[2]


def _tag(env_kwargs: dict | None) -> str:
    """Row-id suffix of a calibration setting: "" or "@key=value,key=value"."""
    return "@" + ",".join(f"{k}={v}" for k, v in env_kwargs.items()) if env_kwargs else ""


def _row(id_, paper, quantity, paper_value, value, unit, tolerance, holds, setting):
    return {
        "id": id_,
        "paper": paper,
        "quantity": quantity,
        "paper_value": paper_value,
        "value": value,
        "unit": unit,
        "tolerance": tolerance,
        "holds": bool(holds),
        "setting": setting,
    }


def cliff_flat_walk_rows(cycles: int = 5) -> list[dict]:
    """Rows 1-3 (Zhang et al. 2024 §5.1): FASM standing, at the tripod switch, and its walking band.

    Same protocol as tests/hexapod_envs/envs/test_cliff_walk.py: 150 standing steps then `cycles`
    tripod cycles.
    """
    import gymnasium as gym

    import hexapod_envs  # noqa: F401  (registers the env ids)
    from agents.policy import episode_infos
    from agents.tripod_gait import TripodGaitPolicy

    steps = 150 + cycles * 300 + 10
    env = gym.make(
        "HexapodCliffWalk-v0", terrain="flat", action_mode="joint", max_episode_steps=steps
    )
    infos = episode_infos(env, TripodGaitPolicy(env), seed=0, max_steps=steps)
    env.close()
    standing = float(np.median([i["fasm_margin_deg"] for i in infos[10:150]]))
    switches = [
        infos[k]["fasm_margin_deg"]
        for k in range(151, len(infos))
        if len(infos[k - 1]["stance_legs"]) > 3 and len(infos[k]["stance_legs"]) == 3
    ]
    walking = np.array([i["fasm_margin_deg"] for i in infos[151:]])
    setting = f"HexapodCliffWalk-v0 terrain=flat, tripod gait, seed 0, {cycles} cycles"
    sw = float(np.median(switches))
    return [
        _row(
            "1",
            "000",
            "FASM standing on six legs (median)",
            48.0,
            round(standing, 2),
            "deg",
            "46-50",
            46.0 <= standing <= 50.0,
            setting,
        ),
        _row(
            "2",
            "000",
            "FASM at the switch to three legs (median)",
            31.41,
            round(sw, 2),
            "deg",
            "29-33",
            29.0 <= sw <= 33.0,
            setting + f", {len(switches)} switches",
        ),
        _row(
            "3",
            "000",
            "FASM band while walking (min, max)",
            [21.0, 51.0],
            [round(float(walking.min()), 2), round(float(walking.max()), 2)],
            "deg",
            "within 18-53",
            walking.min() >= 18.0 and walking.max() <= 53.0,
            setting,
        ),
    ]


def table_ii_rows() -> list[dict]:
    """Row 5 (Zhang et al. 2024 Table II): adjustment leg for each of the six tipping edges."""
    from agents.tipping.judgment import select_adjustment_leg
    from hexapod_envs.robots.heavy_duty import TRIPODS

    t1, t2 = TRIPODS
    table = [
        (t1, ("LF", "LR"), "LM"),
        (t1, ("LR", "RM"), "RR"),
        (t1, ("RM", "LF"), "RF"),
        (t2, ("LM", "RF"), "LF"),
        (t2, ("RF", "RR"), "RM"),
        (t2, ("RR", "LM"), "LR"),
    ]
    ok = sum(
        select_adjustment_leg(s, e) == leg and select_adjustment_leg(s, e[::-1]) == leg
        for s, e, leg in table
    )
    return [
        _row(
            "5",
            "000",
            "Table II adjustment legs matched",
            6,
            int(ok),
            "of 6",
            "6/6",
            ok == 6,
            "agents.tipping.judgment.select_adjustment_leg, both edge orders",
        )
    ]


def upu_kinematics_rows() -> list[dict]:
    """Row 12 (Li et al. 2018 §4): limb 1 length at (80, 0, 443) mm, and the IK/FK round trip."""
    from hexapod_envs.robots.upu.kinematics import forward_kinematics, inverse_kinematics
    from hexapod_envs.robots.upu.params import UpuParams

    p = UpuParams()
    point = np.array([0.080, 0.0, 0.443])
    lengths = inverse_kinematics(point, p)
    limb = float(lengths[0]) * 1e3
    back = np.asarray(forward_kinematics(lengths, p), dtype=float)
    err = float(np.linalg.norm(np.ravel(back)[:3] - point)) * 1e3
    setting = "UpuParams() defaults, upper platform at (80, 0, 443) mm"
    return [
        _row(
            "12",
            "003",
            "limb 1 length at (80, 0, 443) mm",
            457.7,
            round(limb, 3),
            "mm",
            "+-0.05",
            abs(limb - 457.7) <= 0.05,
            setting,
        ),
        _row(
            "12b",
            "003",
            "IK -> FK round-trip error",
            0.0,
            round(err, 9),
            "mm",
            "< 1e-6",
            err < 1e-6,
            setting,
        ),
    ]


ATHENA_ROWS = (
    # (id, terrain, quantity, paper value, unit, tolerance) of rows 8-11d (Coelho et al. 2024
    # §5.2); the measured value and whether it holds come from _athena_values.
    ("8", "ramp", "ramp torso height change", 60.77, "%", ">= +40"),
    ("9", "ramp", "ramp roll-rate change", -35.98, "%", "< 0"),
    ("10", "ramp", "ramp pitch-rate change", -11.92, "%", "<= 0"),
    (
        "11",
        "blocks",
        "blocks torso-contact steps, posture / simple",
        (0, ">0"),
        "steps",
        "posture 0 in >= 3 of 4 seeds, simple > 0 in all",
    ),
    ("11b", "blocks", "blocks pitch-rate change", 54.0, "%", "same sign as paper"),
    ("11c", "blocks", "blocks roll-rate change", 82.0, "%", "same sign as paper"),
    ("11d", "ramp", "ramp median torso height, simple control", 0.068, "m", "+-0.005"),
)


def athena_rows(
    seeds=range(4),
    steps: int = 1200,
    env_kwargs: dict | None = None,
    blocks_kwargs: dict | None = None,
    model: Mapping = CALIBRATED_MODEL,
    tag: str | None = None,
) -> list[dict]:
    """Rows 8-11 (Coelho et al. 2024 §5.2): posture vs simple control on the ramp and the block bed,
    measured with experiments.athena_posture.study.compare (the posture study's protocol) on the
    robot `model` (default: the calibrated one, `CALIBRATED_MODEL`; {}: the -v0 env's defaults).

    `env_kwargs` apply to both terrains, `blocks_kwargs` to the block bed only; each row's id gets
    the suffix `tag`, or "@" + the kwargs of its terrain.
    """
    seeds = list(seeds)
    kwargs = {
        "ramp": dict(env_kwargs or {}),
        "blocks": {**(env_kwargs or {}), **(blocks_kwargs or {})},
    }
    measured = _athena_compare(seeds, steps, model, kwargs)
    n = len(seeds)
    values = _athena_values(measured["ramp"], measured["blocks"], n)
    settings = _athena_settings(kwargs, model, n, steps)
    touched = measured["blocks"]["summary"]["posture"]["episodes_with_collision"]
    notes = {"11": f"; posture touched in {touched} of {n} episodes"}
    rows = []
    for id_, terrain, quantity, paper_value, unit, tolerance in ATHENA_ROWS:
        value, holds = values[id_]
        rows.append(
            _row(
                id_ + (_tag(kwargs[terrain]) if tag is None else tag),
                "002",
                quantity,
                list(paper_value) if isinstance(paper_value, tuple) else paper_value,
                value,
                unit,
                tolerance,
                holds,
                settings[terrain] + notes.get(id_, ""),
            )
        )
    return rows


def _athena_compare(
    seeds: list[int], steps: int, model: Mapping, kwargs: dict[str, dict]
) -> dict[str, dict]:
    """Posture vs simple control on each terrain ("ramp", "blocks": its env kwargs in `kwargs`)
    with experiments.athena_posture.study.compare, `steps` control steps per seed: the terrain's
    `summary` (per controller) and `change_pct` (posture vs simple, %)."""
    from experiments.athena_posture.study import compare

    measured = {}
    for terrain in ("ramp", "blocks"):
        result = compare(terrain, seeds, steps=steps, **model, **kwargs[terrain])
        measured[terrain] = {"summary": result["summary"], "change_pct": result["change_pct"]}
    return measured


def _athena_values(ramp: dict, blocks: dict, n: int) -> dict[str, tuple[object, bool]]:
    """(value, holds) of each row of ATHENA_ROWS from the terrains' comparisons (see
    _athena_compare) over `n` seeds; each test is the row's tolerance phrase. Rate and height
    changes in % (2 decimals), torso-contact counts in control steps, the height in m."""
    rc, bc = ramp["change_pct"], blocks["change_pct"]
    bs, bp = blocks["summary"]["simple"], blocks["summary"]["posture"]
    simple_height = ramp["summary"]["simple"]["height_median"]

    def r(x):
        return None if x is None else round(float(x), 2)

    contact_steps = [bp["torso_collision_steps"], bs["torso_collision_steps"]]
    posture_free = n - bp["episodes_with_collision"]
    return {
        "8": (r(rc["height"]), rc["height"] >= 40.0),
        "9": (r(rc["roll_rate"]), rc["roll_rate"] < 0.0),
        "10": (r(rc["pitch_rate"]), rc["pitch_rate"] <= 0.0),
        "11": (contact_steps, posture_free >= 3 and bs["episodes_with_collision"] == n),
        "11b": (r(bc["pitch_rate"]), bc["pitch_rate"] > 0),
        "11c": (r(bc["roll_rate"]), bc["roll_rate"] > 0),
        "11d": (round(simple_height, 4), abs(simple_height - 0.068) <= 0.005),
    }


def _athena_settings(kwargs: dict[str, dict], model: Mapping, n: int, steps: int) -> dict:
    """The `setting` text of each terrain's rows: env, robot model, the terrain's kwargs (or the
    env defaults they change: servo gain, block size, physics step) and the protocol."""
    from hexapod_envs.envs.irregular_terrain import IrregularTerrainSettings

    protocol = (
        f"seeds 0-{n - 1} x {steps} steps, medians of per-cycle RMS, posture vs simple "
        "(paper gains)"
    )
    env_defaults = IrregularTerrainSettings()
    default = (
        f"servo_kp {env_defaults.servo_kp:g} N m/rad, "
        f"{env_defaults.block_size[0]:g} m blocks, {env_defaults.physics_dt * 1e3:g} ms step"
    )
    robot = f"calibrated model {dict(model)}" if model else "default env"
    return {
        t: f"HexapodIrregularTerrain-v0 {robot} ({kwargs[t] or default}), {protocol}"
        for t in kwargs
    }


def ditch_episode(seed: int = 0, **env_kwargs) -> dict:
    """One HexapodDitchCrossing-v0 episode with UpuGaitPolicy: success, minimum static margin."""
    import gymnasium as gym

    import hexapod_envs  # noqa: F401  (registers the env ids)
    from agents.policy import episode_infos
    from agents.upu_gait import UpuGaitPolicy

    env = gym.make("HexapodDitchCrossing-v0", **env_kwargs)
    policy = UpuGaitPolicy(env)
    infos = episode_infos(env, policy, seed=seed)[1:]  # the steps' infos
    info = infos[-1]
    margins = [i["static_margin_m"] for i in infos]
    env.close()
    return {
        "status": policy.status,
        "success": bool(info["is_success"]) and not info["is_tipped_over"],
        "min_margin_m": float(np.min(margins)),
    }


DITCHES = (  # (id, width m, depth m, action mode, seed): the paper's and two others
    ("14", 0.35, 0.14, "residual", 0),
    ("14b", 0.25, 0.10, "joint", 1),
    ("14c", 0.45, 0.15, "joint", 1),
)


def ditch_rows(env_kwargs: dict | None = None) -> list[dict]:
    """Rows 13-14 (Li et al. 2018 §5-7): flat-walk static margin; the paper's 350 x 140 mm ditch
    and two other sizes crossed with a positive margin at every control step. With
    `env_kwargs` (e.g. UPU_FINER_STEP) the row ids get the suffix "@" + the kwargs."""
    extra = dict(env_kwargs or {})
    tag = _tag(extra)
    shown = f" {extra}" if extra else ""
    flat = ditch_episode(seed=2, terrain="flat", action_mode="joint", **extra)
    rows = [
        _row(
            "13" + tag,
            "003",
            "flat walk minimum static margin",
            "> 0",
            round(flat["min_margin_m"] * 1e3, 2),
            "mm",
            "> 0",
            flat["success"] and flat["min_margin_m"] > 0,
            f"HexapodDitchCrossing-v0 terrain=flat{shown}, joint mode, UpuGaitPolicy, seed 2",
        ),
    ]
    for id_, width, depth, mode, seed in DITCHES:
        r = ditch_episode(
            seed=seed, action_mode=mode, ditch_width=width, ditch_depth=depth, **extra
        )
        rows.append(
            _row(
                id_ + tag,
                "003",
                f"{width * 1e3:.0f} mm wide x {depth * 1e3:.0f} mm deep ditch "
                "crossed (min static margin)",
                "crossed" if id_ == "14" else "(not in paper)",
                round(r["min_margin_m"] * 1e3, 2),
                "mm",
                "crossed, margin > 0 at every step",
                r["success"] and r["min_margin_m"] > 0,
                f"HexapodDitchCrossing-v0{shown} {mode} mode, UpuGaitPolicy, seed {seed}; "
                f"planner status {r['status']}",
            )
        )
    return rows


# A quarter of the 3-UPU's and ATHENA's default physics steps (2 ms, 2.5 ms): rows with these
# suffixes show which results are the default step's discretization (`python
# experiments/physics_settings/physics_settings.py --finer`). The heavy-duty robot's rows were
# checked at a quarter of its 2 ms default step (0.5 ms, `physics_settings.py --finer`) with no
# outcome change, so it has no such rows.
UPU_FINER_STEP = {"physics_dt": 0.0005}
ATHENA_FINER_STEP = {"physics_dt": 0.000625}


def ditch_finer_step_rows() -> list[dict]:
    """Rows 13-14 again at a quarter of the 3-UPU's default step."""
    return ditch_rows(env_kwargs=UPU_FINER_STEP)


def athena_finer_step_rows() -> list[dict]:
    """Rows 8-11d again at a quarter of ATHENA's default step."""
    return athena_rows(env_kwargs=ATHENA_FINER_STEP)


def athena_v0_default_rows() -> list[dict]:
    """Rows 8-11d with the -v0 env's robot model (suffix V0_DEFAULT) instead of the calibrated
    one: MuJoCo's default contact softness and 0.002 kg m² of servo rotor inertia."""
    return athena_rows(model={}, tag=V0_DEFAULT)


@functools.cache
def _script(name: str):
    """Load `scripts/<name>.py` as a module (to reuse its measurement code, not duplicate it),
    once per process."""
    import importlib.util

    path = ROOT / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"_repro_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _paper_case_kwargs(scenario: str, stance: str) -> dict:
    """Env kwargs of one Stewart case as the paper runs it (`paper_scenario`), less the case."""
    from hexapod_envs.envs.stewart_tilt import paper_scenario

    kwargs = paper_scenario(scenario, stance)
    del kwargs["scenario"], kwargs["stance"]
    return kwargs


V0_DEFAULT = "@v0 default"
"""Row-id suffix of rows measured with the -v0 env's defaults instead of the paper's scenario
(Stewart: 2 deg/s from 3 s, no stop before 38-44 deg) or the calibrated robot model (ATHENA)."""


def stewart_rows(
    seed: int = 0, cases=None, env_kwargs: dict | None = None, tag: str | None = None
) -> list[dict]:
    """Rows 6, 7, 7b and 7c (Zhang et al. 2024 §5.2) for each Stewart case with
    TippingRecoveryPolicy: adjustment leg, t_s, FASM 0.5 s after landing and its minimum from
    landing to the end, the stability cone's λ.

    Uses `run` / `fasm_at` of scripts/plot_stewart_recovery.py. Each case runs as the paper runs
    it (`hexapod_envs.envs.stewart_tilt.paper_scenario`: the paper's start time, a tilt rate that
    exercises eq. 15, the platform stopping once the robot tips) unless `env_kwargs` is given
    (e.g. {} for the env's defaults); then the row ids get the suffix `tag` (default "@" + the
    kwargs) and row 6 is left out.
    """
    mod = _script("plot_stewart_recovery")
    paper = env_kwargs is None
    tag = "" if paper else (_tag(env_kwargs) if tag is None else tag)
    cases = mod.CASES if cases is None else cases
    rows, legs_ok = [], 0
    for scenario, stance in cases:
        kwargs = _paper_case_kwargs(scenario, stance) if paper else env_kwargs
        ctrl = mod.run(scenario, stance, controlled=True, seed=seed, env_kwargs=kwargs)
        d = ctrl["diagnostics"]
        p_leg, p_ts, _, p_after = mod.PAPER[(scenario, stance)]
        legs_ok += d["adjustment_leg"] == p_leg
        case = f"{scenario} {stance}" + tag
        setting = (
            f"HexapodStewartTilt-v0 scenario={scenario} stance={stance} {kwargs or ''}"
            + (" (paper_scenario)" if paper else "")
            + f", seed {seed}; judged at {d['judgment_time']} s"
        )
        rows.append(_time_budget_row(case, d["t_s"], p_ts, setting))
        rows.append(_cone_row(f"7c.{case}", case, ctrl, setting))
        rows.append(_fasm_after_landing_row(mod, case, scenario, ctrl, p_after, setting))
    if tag:
        return rows
    rows.insert(0, _adjustment_leg_row(legs_ok, len(cases)))
    return rows


def _time_budget_row(case: str, ts: float | None, paper_ts: float, setting: str) -> dict:
    """Row 7b of one Stewart case: the adjustment leg's time budget t_s [s] (eq. 15), which holds
    inside (0.5, 2.5) s, i.e. not at the controller's clamps 0.5 / 3.0 s."""
    return _row(
        f"7b.{case}",
        "000",
        f"t_s, {case}",
        paper_ts,
        None if ts is None else round(ts, 3),
        "s",
        "inside 0.5-2.5, not at a clamp (0.5 / 3.0)",
        ts is not None and 0.5 < ts < 2.5,
        setting,
    )


def _fasm_after_landing_row(
    mod, case: str, scenario: str, ctrl: dict, paper_after, setting: str
) -> dict:
    """Row 7 of one Stewart case: FASM [deg] 0.5 s after the adjustment leg lands and its minimum
    from then to the end of run `ctrl` (scripts/plot_stewart_recovery.py's `mod.run`).

    Holds when the first is at least 35 deg (20 deg on the side case) and the second never below
    the tipping threshold ξ_f, and the robot did not tip; a run whose leg never lands fails.
    """
    from agents.tipping.judgment import XI_F_DEG

    landed = ctrl["diagnostics"]["landing_time"]
    if landed is None:
        return _row(
            f"7.{case}",
            "000",
            f"FASM after landing, {case}",
            paper_after,
            None,
            "deg",
            ">= 35 / 35 / 20",
            False,
            setting + "; never landed",
        )
    after = mod.fasm_at(ctrl, landed + 0.5)
    later = ctrl["fasm"][ctrl["t"] >= landed + 0.5]
    low = float(later.min()) if len(later) else float("nan")
    need = 20.0 if scenario == "side" else 35.0
    return _row(
        f"7.{case}",
        "000",
        f"FASM 0.5 s after landing / min to end, {case}",
        paper_after,
        [round(after, 2), round(low, 2)],
        "deg",
        f">= {need:g} after 0.5 s, never below xi_f={XI_F_DEG:g} after",
        after >= need and low >= XI_F_DEG and not ctrl["tipped"],
        setting + f"; platform tilt at end {ctrl['tilt'][-1]:.1f} deg",
    )


def _adjustment_leg_row(legs_ok: int, n_cases: int) -> dict:
    """Row 6: in how many of the Stewart cases the judgment chose the paper's adjustment leg
    (Zhang et al. 2024 Table II); holds when all of them match."""
    return _row(
        "6",
        "000",
        "Stewart adjustment leg as paper",
        6,
        legs_ok,
        "of 6",
        "6/6",
        legs_ok == n_cases,
        "HexapodStewartTilt-v0, six cases as paper_scenario, seed 0",
    )


def stewart_v0_default_rows() -> list[dict]:
    """Rows 7, 7b and 7c with the env's defaults (suffix V0_DEFAULT): 2 deg/s from 3 s and no
    stop before 38-44 deg, which the paper's scenario replaces."""
    return stewart_rows(env_kwargs={}, tag=V0_DEFAULT)


def cliff_judgment_rows(seed: int = 0) -> list[dict]:
    """Row 4 (Zhang et al. 2024 §5.1): the tipping judgment fires before the gait alone tips over.

    Uses `rollout` of scripts/plot_cliff_recovery.py: judgment time of GaitWithRecoveryPolicy
    (joint mode) and the tip-over time of TripodGaitPolicy alone, same seed and cliff.
    """
    mod = _script("plot_cliff_recovery")
    gait = mod.rollout(*mod.RUNS["gait only"], seed)
    ctrl = mod.rollout(*mod.RUNS["gait + recovery (joint mode)"], seed)
    judged = ctrl["diagnostics"]["judgment_time"]
    tipped_at = float(gait["t"][-1]) if gait["tipped"] else None
    holds = judged is not None and tipped_at is not None and judged < tipped_at
    return [
        _row(
            "4",
            "000",
            "cliff: judgment time / gait-alone tip-over time",
            [22.08, 22.36],
            [
                None if judged is None else round(judged, 2),
                None if tipped_at is None else round(tipped_at, 2),
            ],
            "s",
            "judgment fires before",
            holds,
            f"HexapodCliffWalk-v0 default cliff, seed {seed}; recovery run tipped="
            f"{ctrl['tipped']} (our walk starts at 3 s, the paper's cliff is reached later)",
        )
    ]


ATHENA_PREVIOUS_DEFAULT = {"servo_kp": 8.0}
ATHENA_PREVIOUS_BLOCKS = {"block_size": (0.1, 0.1)}
"""The ATHENA env defaults before its calibration (rows with these suffixes): servo_kp 8 and
0.1 m blocks. How the defaults (kp 6.8, 0.25 m blocks) were chosen, measured: README.md."""


BLOCK_BEDS = range(20)
"""Beds (seeds) of the block-bed rows with their bootstrap intervals (`athena_block_beds_rows`)."""


def athena_block_beds_rows(seeds=BLOCK_BEDS, steps: int = 1200) -> list[dict]:
    """Rows 11-11c again on 20 block beds, each change with its 95 % percentile-bootstrap
    interval over the beds (`experiments.athena_posture.study.change_interval`): on 4 beds the
    pooled rate medians swing too much to settle the sign of a change (a tighter solver tolerance
    alone moves seeds 0-3's pitch change from +45 % to +39 %, a looser one to -32 %)."""
    from experiments.athena_posture.study import change_interval, compare

    result = compare("blocks", seeds, steps=steps, **CALIBRATED_MODEL)
    n = len(result["simple"])
    summary = result["summary"]
    touched = summary["posture"]["episodes_with_collision"]
    setting = (
        f"HexapodIrregularTerrain-v0 calibrated model {dict(CALIBRATED_MODEL)}, blocks, "
        f"seeds 0-{n - 1} x {steps} steps, "
        "medians of per-cycle RMS pooled over the beds, posture vs simple (paper gains); "
        "interval: 95 % percentile bootstrap over the beds"
    )
    rows = [
        _row(
            "11",
            "002",
            "blocks torso-contact steps, posture / simple",
            [0, ">0"],
            [
                summary["posture"]["torso_collision_steps"],
                summary["simple"]["torso_collision_steps"],
            ],
            "steps",
            "posture 0 on >= 3/4 of the beds, simple > 0 on all",
            4 * (n - touched) >= 3 * n and summary["simple"]["episodes_with_collision"] == n,
            setting + f"; posture touched on {touched} of {n} beds",
        )
    ]
    for id_, metric, paper_value in (("11b", "pitch_rate", 54.0), ("11c", "roll_rate", 82.0)):
        estimate, low, high = change_interval(result, metric)
        rows.append(
            _row(
                id_,
                "002",
                f"blocks {metric.replace('_', '-')} change [95 % interval]",
                paper_value,
                [round(estimate, 2), round(low, 2), round(high, 2)],
                "%",
                "same sign as paper, interval excluding 0",
                low > 0,
                setting,
            )
        )
    for row in rows:
        row["id"] += f"@seeds 0-{n - 1}"
    return rows


def athena_previous_default_rows() -> list[dict]:
    """Rows 8-11 with the ATHENA env defaults before the calibration (kp 8, 0.1 m blocks)."""
    return athena_rows(
        env_kwargs=ATHENA_PREVIOUS_DEFAULT, blocks_kwargs=ATHENA_PREVIOUS_BLOCKS, model={}
    )


PAPER_CONE_RATIO = 0.5
"""λ of the stability cone in Zhang et al. 2024 §5.2 (the force distribution's default)."""


def _cone_counts(ctrl: dict) -> tuple[int, int, int]:
    """(QP steps at the paper's λ, at a wider λ, without the cone) of a Stewart run."""
    ratios = [r for r in ctrl["cone_ratios"] if r is not None]
    at_paper = sum(1 for r in ratios if r == PAPER_CONE_RATIO)
    dropped = sum(1 for r in ratios if math.isnan(r))  # the QP was solved without the cone
    return at_paper, len(ratios) - at_paper - dropped, dropped


def _status_counts(ctrl: dict) -> str:
    """The QP statuses of a Stewart run's supported steps, e.g. "optimal 1054"."""
    counts = Counter(str(status) for status in ctrl["qp_status"])
    return ", ".join(f"{status} {n}" for status, n in sorted(counts.items())) or "none"


def _cone_row(id_: str, case: str, ctrl: dict, setting: str) -> dict:
    at_paper, wider, dropped = _cone_counts(ctrl)
    return _row(
        id_,
        "000",
        f"QP steps with the stability cone at lambda 0.5 / wider / without, {case}",
        "all at 0.5",
        [at_paper, wider, dropped],
        "steps",
        "all at lambda 0.5",
        wider == 0 and dropped == 0,
        setting + f"; t_s {ctrl['diagnostics']['t_s']}, QP status per supported step "
        f"{_status_counts(ctrl)}, recovery controller's default ladder (lambda 0.5, then "
        "0.65 / 0.8 / 0.95, then no cone; cone radius = lambda x the support centroid's "
        "distance to the nearest support edge)",
    )


def stewart_paper_cone_rows(seed: int = 0) -> list[dict]:
    """Row 7d per Stewart case (the paper's scenario): the recovery with the cone at the paper's
    λ only (no wider λ; a step whose QP is infeasible at λ = 0.5 is solved without the cone and
    counted), so the infeasibility is reported instead of relaxed."""
    mod = _script("plot_stewart_recovery")
    rows = []
    for scenario, stance in mod.CASES:
        kwargs = _paper_case_kwargs(scenario, stance)
        ctrl = mod.run(
            scenario, stance, controlled=True, seed=seed, env_kwargs=kwargs, cone_ratios=()
        )
        at_paper, _, dropped = _cone_counts(ctrl)
        outcome = "tipped" if ctrl["tipped"] else "recovers"
        rows.append(
            _row(
                f"7d.{scenario} {stance}",
                "000",
                f"recovery with the cone at lambda 0.5 only: outcome, QP steps feasible / "
                f"infeasible, {scenario} {stance}",
                ["recovers", "all feasible"],
                [outcome, at_paper, dropped],
                "steps",
                "recovers, no infeasible step",
                outcome == "recovers" and dropped == 0,
                f"HexapodStewartTilt-v0 scenario={scenario} stance={stance} {kwargs} "
                f"(paper_scenario), TippingRecoveryPolicy(cone_ratios=()), seed {seed}; "
                "infeasible steps are solved without the cone",
            )
        )
    return rows


STEWART_PAPER_REACH = {"hold_depth": 1.79}
"""Calibration setting for row 6b: the hold posture's feet 1.79 m below the coxa origins instead
of 1.95 m (env kwarg hold_depth; the paper gives neither the hold posture nor all of the leg
geometry). The paper's reach model (eqs. 10-12) then picks its foothold at the paper's height,
(0, +-1837, -1786) mm against (0, +-1894, -1783) mm; at 1.95 m it lies 163 mm lower and 11 mm
inside the tipping edge. Measured for the side case, LF-LR-RM, with the env's default tilt
(2 deg/s, no stop): hold depth 1.95 m tips, 1.85 / 1.79 / 1.70 m recover (margin 0.5 s after
landing 15.5 / 15.2 / 14.7 deg, paper 21.5); in the paper's scenario (the platform stops once the
robot tips) 1.95 m and 1.79 m both recover."""


def stewart_paper_reach_rows(seed: int = 0, env_kwargs: dict | None = None) -> list[dict]:
    """Row 6b: the side cases (the paper's scenario) with the paper's reach model (eqs. 10-12)
    instead of ours; with `env_kwargs` (e.g. STEWART_PAPER_REACH, added to the paper's
    scenario) the row ids get the suffix "@" + the kwargs."""
    mod = _script("plot_stewart_recovery")
    tag = _tag(env_kwargs)
    rows = []
    for stance in ("LF-LR-RM", "LM-RF-RR"):
        kwargs = {**_paper_case_kwargs("side", stance), **(env_kwargs or {})}
        ctrl = mod.run(
            "side", stance, controlled=True, seed=seed, env_kwargs=kwargs, reach_model="paper"
        )
        d = ctrl["diagnostics"]
        foot = d["foothold"]
        p_foot = mod.PAPER[("side", stance)][2]
        landed = d["landing_time"]
        after = "never landed" if landed is None else f"{mod.fasm_at(ctrl, landed + 0.5):.1f} deg"
        rows.append(
            _row(
                f"6b.side {stance}{tag}",
                "000",
                f"side {stance} recovers with the paper's reach model (foothold)",
                ["recovers", list(p_foot)],
                [
                    "tipped" if ctrl["tipped"] else "recovers",
                    None if foot is None else [round(float(v) * 1e3) for v in foot],
                ],
                "mm",
                "no tip-over",
                not ctrl["tipped"],
                f"HexapodStewartTilt-v0 scenario=side stance={stance} {kwargs} "
                f"(paper_scenario{' + ' + str(env_kwargs) if env_kwargs else ''}), "
                f"reach_model='paper', seed {seed}; FASM 0.5 s after landing {after}",
            )
        )
    return rows


def stewart_paper_reach_calibrated_rows() -> list[dict]:
    """Row 6b with the calibrated hold posture (STEWART_PAPER_REACH)."""
    return stewart_paper_reach_rows(env_kwargs=STEWART_PAPER_REACH)


CHEAP = {"000": (table_ii_rows,), "003": (upu_kinematics_rows,)}
FULL = {
    "000": (
        cliff_flat_walk_rows,
        cliff_judgment_rows,
        table_ii_rows,
        stewart_rows,
        stewart_paper_cone_rows,
        stewart_paper_reach_rows,
        stewart_paper_reach_calibrated_rows,
        stewart_v0_default_rows,
    ),
    "002": (
        athena_rows,
        athena_block_beds_rows,
        athena_previous_default_rows,
        athena_finer_step_rows,
        athena_v0_default_rows,
    ),
    "003": (upu_kinematics_rows, ditch_rows, ditch_finer_step_rows),
}


def collect(only: str | None = None, quick: bool = False) -> list[dict]:
    """All rows (or only paper `only`, one of "000", "002", "003"); `quick` = cheap rows only."""
    groups = CHEAP if quick else FULL
    if only is not None and only not in FULL:
        raise ValueError(f"only must be one of {sorted(FULL)}, got {only!r}")
    rows = []
    for paper, funcs in groups.items():
        if only is None or paper == only:
            for f in funcs:
                rows.extend(f())
    return rows


NOTES = (
    "6, 7, 7b, 7c, 7d, 6b (Stewart platform) run each case as the paper runs it "
    "(hexapod_envs.envs.stewart_tilt.paper_scenario): the stance feet as wide as the paper's "
    "(|y| = 1.9 m), the tilt starting after the paper's adjustment stage (7 s with LF-LR-RM in "
    "stance, 5 s with LM-RF-RR), 8 deg/s, and the platform stopping once the robot tips "
    "(FASM < xi_f; it decelerates over 1 s and rests 4 deg further), as the paper's margins after "
    "landing (about 40 / 45 / 21.5 deg, holding) require. Rows @v0 default (the env's defaults: "
    "feet at |y| = 1.7 m, 2 deg/s from 3 s, no stop before 38-44 deg) keep tilting and the margin "
    "falls back to 13.5 / 3.6 deg, t_s is the 3 s clamp and the cone is infeasible at lambda 0.5 "
    "climbing and descending.",
    "7b (t_s, 1.74-1.92 s against the paper's 0.74-2.31 s): the paper gives no tilt rate. Its "
    "judgment times (7.48 / 4.85 / 8.83 s after the tilt starts) fit 1.2-2.5 deg/s at our "
    "judgment tilts (9-10 deg climbing or descending, 22-25 deg sideways), at which eq. 15 "
    "forecasts 10-12 s and t_s is the 3 s clamp (rows @v0 default, 2 deg/s). Its t_s need the "
    "FASM to fall at 6-19 deg/s at the judgment, and they differ threefold between mirror-image "
    "cases (climbing 0.74 vs 2.31 s, descending 1.0 vs 1.3 s, sideways 2.1 vs 1.48 s) that a "
    "left-right symmetric robot on a mirrored motion cannot tell apart: they depend on how the "
    "paper estimated the margin's rate and acceleration, which it does not say. The judgment "
    "times and the t_s cannot both be matched; the rate reproduces t_s, and the judgment comes "
    "1.7 s (climb, descend) and 3.7 s (side) after the tilt starts. The paper's shortest t_s are "
    "not reached with the recovery intact: at 9-12 deg/s climbing the judgment comes within 0.6 "
    "s of the end of the platform's 1 s ramp and the fitted margin acceleration swings (+2.5, "
    "-17, +100 deg/s^2): t_s is the 3 s clamp, or 0.70 s (10 deg/s) with the foot landing "
    "unloaded (12.4 deg after landing).",
    "7c / 7d (stability cone at lambda 0.5): holds in the paper's scenario. With the env's "
    "narrower default stance (rows @v0 default, feet at |y| = 1.7 m) the QP is infeasible at "
    "lambda 0.5 on every supported step climbing and descending: measured at the landing "
    "(climb, LF-LR-RM, 7 deg/s), the support centroid lies 0.60 m behind the CoG's projection, "
    "d_min is 1.51 m, and the inscribed pyramid of eq. 24 (its S_M carries the 1/sqrt(2)) "
    "reaches lambda d_min / sqrt(2) = 0.53 m along the body's x axis, which bounds the tipping "
    "force of the side edges (parallel to x) at any tilt; at |y| = 1.9 m d_min is 1.57 m and "
    "the QP is feasible. It is a knife edge the paper's geometry does not settle either: with the "
    "paper's foothold coordinates the QP is feasible with the CoG above the body origin (0.57 m "
    "against 0.56 m) and infeasible with it 0.1 m forward, where the paper puts it.",
    "9 (ramp roll rate, +5.5 % vs -36 %): with the servo model calibrated to the paper's simple-"
    "control sag (env default servo_kp 6.8 N m/rad; 0.0676 m vs 0.068 m, row 11d) the simple "
    "control drags its torso on the slope, which damps its roll, and posture control's roll-rate "
    "RMS ends 5.5 % above it (+1.9 % at the former 2 ms step). With the previous default (kp 8, "
    "rows @servo_kp=8.0) rows 9 and 10 hold (-15.4 %, -34.0 %) but the height gain is only "
    "+15 % (row 8) and the sag 0.089 m: no single stiffness reproduces all four ramp rows. The "
    "row is also the physics step's: posture control's ramp roll-rate RMS falls as the step "
    "shrinks (0.0445 rad/s at 2.5 ms, 0.0391 at 0.625 ms), and at a quarter of the default step "
    "(rows @physics_dt=0.000625) row 9 holds; the change is -2.5 % at 1.25 ms and -8.4 % at "
    "0.3125 ms (benchmarks/README.md, convergence of the default timesteps).",
    "11b, 11c, 11@seeds 0-19 (blocks; row 11 itself holds): on the calibrated bed (0.25 m "
    "blocks, env default; the paper gives no size) posture control touches in 1 of seeds 0-3 "
    "(5 steps) and on 10 of 20 beds (rows "
    "@seeds 0-19: 673 steps against the simple controller's 15273), so it keeps the torso off "
    "the blocks on most steps, not on all beds. The paper's pitch/roll-rate rises (+54 % / "
    "+82 %) are not reproduced: on seeds 0-3 posture control lowers both rates (-36 % / -30 %), "
    "and on 20 beds the changes are -8.0 % and -21.7 % with 95 % intervals of [-37.1, +51.2] "
    "and [-33.6, +19.4] %, whose sign is not settled. The block size was chosen on seeds 0-3 at "
    "the former 2 ms physics step, where their changes were +45 % / +34 % (20 beds: +13.8 % and "
    "-10.8 %); the timestep, a looser solver tolerance (1e-6 instead of 1e-8) or RK4 each flip "
    "seeds 0-3's changes, so the 20-bed rows with their intervals are the ones to read. On the "
    "previous 0.1 m blocks with kp 8 posture control touched in 4 of 4 episodes (83 steps), "
    "changed the pitch rate by +4 % and lowered the roll rate by 22 %: the simple controller's "
    "torso knocked on the many block edges, which posture control mostly avoids.",
    "6b (paper's reach model, side cases): in the paper's scenario both recover with the "
    "default hold depth (foothold (0, +-1889, -1946) mm, 163 mm lower than the paper's: our "
    "hold posture stands taller), margin 0.5 s after landing below the paper's 21.5 deg (see "
    "the rows' settings); with the hold posture calibrated to the paper's foothold height "
    "(STEWART_PAPER_REACH, hold_depth 1.79 m) it picks (0, +-1837, -1786) mm. With the env's "
    "default tilt (no stop) both side cases tip with the paper's reach model at 1.95 m. The env "
    "default stays the kinematic reach model, on which the shipped agents were trained.",
    "14, 14c @physics_dt=0.0005 (3-UPU, a quarter of the default 2 ms step): the reference gait "
    "tips on the paper's ditch at 97.8 s and on the 450 x 150 mm ditch; it crosses at every "
    "step from 0.8 to 2.5 ms. When the lower platform lifts its legs the robot stands on the "
    "upper platform's feet with the CoG 14 mm inside their triangle; at the finer step the legs "
    "U2 and U3 give under the shifted load, the platform sinks onto L1 (on the ditch floor) and "
    "rolls over. The default step's numerical damping of the servos holds that thin margin; on "
    "the 20 test tasks of the shipped report the planner succeeds on 5 instead of 16 at 0.5 ms "
    "(reports/finer_physics), the hybrid agent on 19 and PPO on 18.",
    "4 (cliff): our gait starts walking at 3 s and meets the cliff earlier than the paper's, so "
    "the absolute times differ; the order (judgment before the tip-over) holds.",
)
"""Causes of the rows that fall short, measured (see the rows' settings)."""


HEADLINES = (
    ("1", "000 §5.1", "FASM standing on six legs", "≈ 48°"),
    ("2", "000 §5.1", "FASM at the switch to three legs", "31.41°"),
    ("3", "000 §5.1", "FASM band while walking on flat ground", "≈ 21-51°"),
    ("4", "000 §5.1", "cliff: judgment (FASM < 20°) before the tip-over", "22.08 < 22.36 s"),
    ("5", "000 Table II", "adjustment leg for each tipping edge", "6 of 6"),
    ("6", "000 §5.2", "Stewart platform: the paper's adjustment leg", "6 of 6 cases"),
    ("7.", "000 §5.2", "FASM after landing, held to the end", "≈ 40 / 45 / 21.5°"),
    ("7b.", "000 §5.2", "adjustment time t_s of eq. 15", "0.74-2.31 s"),
    ("7c.", "000 §4.3", "force distribution inside the stability cone (λ 0.5)", "all steps"),
    ("8", "002 §5.2", "ramp: torso height, posture vs simple control", "+60.77 %"),
    ("9", "002 §5.2", "ramp: roll-rate RMS, posture vs simple control", "-35.98 %"),
    ("10", "002 §5.2", "ramp: pitch-rate RMS, posture vs simple control", "-11.92 %"),
    ("11", "002 §5.2", "blocks: posture control keeps the torso off the blocks", "0 contacts"),
    ("12", "003 §4", "limb 1 length at (80, 0, 443) mm", "457.7 mm"),
    ("13", "003 §5", "flat walk: static margin positive at every step", "> 0"),
    ("14", "003 §7", "the 350 x 140 mm ditch crossed with a positive margin", "crossed"),
)
"""The papers' headline results: (row id, or the prefix of the per-case rows "7." / "7b." /
"7c."; paper and section; result; the paper's value), in the order of the report's summary."""


def headline_rows(rows: list[dict], key: str) -> list[dict]:
    """The rows of headline `key`: the row with that id, or for a prefix ending in "." the
    per-case rows of the paper's scenario (ids key + case, without a calibration suffix "@")."""
    if key.endswith("."):
        return [r for r in rows if r["id"].startswith(key) and "@" not in r["id"]]
    return [r for r in rows if r["id"] == key]


def _summary_value(picked: list[dict]) -> str:
    if len(picked) == 1:
        row = picked[0]
        return f"{row['value']} {row['unit']}"
    held = sum(r["holds"] for r in picked)
    values = "; ".join(f"{r['id'].split('.', 1)[1]}: {r['value']}" for r in picked)
    return f"{held} of {len(picked)} cases hold ({values}; {picked[0]['unit']})"


def summary(rows: list[dict]) -> list[str]:
    """The report's summary: one Markdown table line per headline result (HEADLINES) found in
    `rows`, with ours and the verdict (a per-case headline holds when every case holds)."""
    lines = [
        "| row | paper | headline result | paper | ours | verdict |",
        "|---|---|---|---|---|---|",
    ]
    for key, paper, result, paper_value in HEADLINES:
        picked = headline_rows(rows, key)
        if not picked:
            continue
        verdict = "holds" if all(r["holds"] for r in picked) else "**fails**"
        lines.append(
            f"| {key.rstrip('.')} | {paper} | {result} | {paper_value} | "
            f"{_summary_value(picked)} | {verdict} |"
        )
    return lines


def markdown(rows: list[dict]) -> str:
    """The report: the headline summary, then every row as a Markdown table, then the notes."""
    held = sum(r["holds"] for r in rows)
    lines = [
        "# Reproduction of the three papers",
        "",
        "Generated by `python scripts/reproduce_papers.py` (every value simulated or computed",
        "in that run; `holds` compares it with the tolerance). Papers: 000 heavy-duty hexapod",
        "tipping recovery, 002 ATHENA posture control, 003 3-UPU hexapod ditch crossing.",
        "",
        "## Summary: the papers' headline results",
        "",
        *summary(rows),
        "",
        f"All rows: {held} of {len(rows)} hold (the table below also holds the calibration "
        "settings' rows, suffixed @setting, and the checks at a finer physics step).",
        "",
        "## All rows",
        "",
        "| id | paper | quantity | paper | ours | unit | tolerance | holds | setting |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['id']} | {r['paper']} | {r['quantity']} | {r['paper_value']} | {r['value']} "
            f"| {r['unit']} | {r['tolerance']} | {'yes' if r['holds'] else '**no**'} "
            f"| {r['setting']} |"
        )
    lines += ["", "## Rows that do not hold, and caveats (measured)", ""]
    lines += [f"- {note}" for note in NOTES]
    return "\n".join(lines) + "\n"


def _isclose(a, b) -> bool:
    """Equal, or within 1e-6 (relative and absolute) for numbers."""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-6)
    return a == b
