"""Coelho et al. 2024's tripod gait and posture controller (hexapod_envs/robots/athena/gait.py):
closed-form checks."""

import math

import numpy as np
import pytest

from hexapod_envs.robots.athena import kinematics as kin
from hexapod_envs.robots.athena.gait import (
    AthenaPostureController,
    AthenaSensors,
    cubic_bezier,
    cubic_bezier_derivative,
    posture_rotation,
    swing_control_points,
    torso_deviation_from_plane,
)
from hexapod_envs.robots.athena.params import ATHENA, LEG_NAMES, TRIPODS
from hexapod_envs.stability.plane_fit import fit_plane

S, H = 0.06, 0.16
IDX = {leg: i for i, leg in enumerate(LEG_NAMES)}


def _forces(legs, value=5.0):
    f = np.zeros(6)
    f[[IDX[leg] for leg in legs]] = value
    return f


def _sensors(feet, contact_legs, height=ATHENA.standing_torso_height):
    return AthenaSensors(kin.inverse_kinematics_all(feet), _forces(contact_legs), height)


def _run_phase(ctrl, feet, contact_legs, height=ATHENA.standing_torso_height):
    """Step one whole phase with constant sensor readings; returns the commanded feet."""
    for _ in range(ctrl.ticks_per_phase):
        ctrl.step(_sensors(feet, contact_legs, height))
    return ctrl.commanded_feet


def _plane_feet(a=0.0, b=0.0):
    """Standing feet moved vertically onto the body-frame plane z = z0 + a x + b y."""
    feet = kin.standing_foot_positions()
    feet[:, 2] += a * feet[:, 0] + b * feet[:, 1]
    return feet


# ----- Bezier swing (eqs. 19-22, 27) and stance (eq. 23) -----------------------------------
def test_bezier_swing_endpoints_tangents_and_apex():
    p0 = np.array([0.2, 0.13, -0.084])
    c = -0.012  # k_z delta_z
    pts = swing_control_points(p0, S, H, c)
    np.testing.assert_allclose(cubic_bezier(pts, 0.0), p0)
    np.testing.assert_allclose(cubic_bezier(pts, 1.0), p0 + [S, 0, c])
    np.testing.assert_allclose(cubic_bezier_derivative(pts, 0.0), [3 * S / 4, 0, H])
    np.testing.assert_allclose(cubic_bezier_derivative(pts, 1.0), [3 * S / 4, 0, 3 * c - H])
    np.testing.assert_allclose(cubic_bezier(pts, 0.5), p0 + [S / 2, 0, H / 4 + c / 8])
    xs = [cubic_bezier(pts, u)[0] for u in np.linspace(0, 1, 41)]
    assert np.all(np.diff(xs) > 0)  # the foot only moves forward


def test_first_phase_half_stride_then_symmetric_strides_about_the_standing_footholds():
    ctrl = AthenaPostureController(stride=S, swing_height=H)
    home = kin.standing_foot_positions()
    feet = home.copy()
    swing0, stance0 = TRIPODS
    history = []
    for phase in range(4):
        stance = TRIPODS[(phase + 1) % 2]
        for _ in range(ctrl.ticks_per_phase):
            targets = ctrl.step(_sensors(feet, stance))
            feet = ctrl.commanded_feet
            np.testing.assert_allclose(kin.forward_kinematics_all(targets), feet, atol=1e-12)
            history.append(feet.copy())
        assert ctrl.last_estimate.stance_legs == stance
    history = np.array(history)
    n = ctrl.ticks_per_phase
    for leg in swing0:  # swing first: to +s/2, then back and forth between +-s/2
        i = IDX[leg]
        np.testing.assert_allclose(history[n - 1, i] - home[i], [S / 2, 0, 0], atol=1e-12)
        np.testing.assert_allclose(history[2 * n - 1, i] - home[i], [-S / 2, 0, 0], atol=1e-12)
        np.testing.assert_allclose(history[3 * n - 1, i] - home[i], [S / 2, 0, 0], atol=1e-12)
        lift = history[n : 2 * n, i, 2] - home[i, 2]
        np.testing.assert_allclose(lift, 0.0, atol=1e-12)  # stance in phase 1: on the ground
        lift = history[2 * n : 3 * n, i, 2] - home[i, 2]
        assert lift.max() == pytest.approx(ctrl.swing_apex, abs=1e-3)
    for leg in stance0:  # stance first: to -s/2 linearly, then swing to +s/2
        i = IDX[leg]
        steps = np.diff(history[n : 2 * n, i], axis=0)  # phase 1 is a swing for these legs
        np.testing.assert_allclose(history[n - 1, i] - home[i], [-S / 2, 0, 0], atol=1e-12)
        np.testing.assert_allclose(history[2 * n - 1, i] - home[i], [S / 2, 0, 0], atol=1e-12)
        assert np.all(steps[:, 0] > 0)
        stance_steps = np.diff(history[2 * n : 3 * n, i], axis=0)  # phase 2: linear stance
        np.testing.assert_allclose(stance_steps, np.tile([-S / n, 0, 0], (n - 1, 1)), atol=1e-12)


# ----- posture control (eqs. 24-31) --------------------------------------------------------
@pytest.mark.parametrize("k_alpha", [0.0, 0.5, 1.0])
def test_pitch_correction_has_the_right_sign_and_size(k_alpha):
    phi = math.radians(6.0)  # ground rises ahead: torso is nose down by phi relative to it
    feet = _plane_feet(a=math.tan(phi))
    stance = TRIPODS[1]  # stance tripod of the first phase
    ctrl = AthenaPostureController(k_alpha=k_alpha)
    end = _run_phase(ctrl, feet, stance)
    est = ctrl.last_estimate
    assert est.plane_legs == stance
    assert est.delta_pitch == pytest.approx(phi, abs=1e-12)
    assert est.delta_roll == pytest.approx(0.0, abs=1e-12)
    stance_end = end[[IDX[leg] for leg in stance]]
    # The feet are rotated about the torso centre by R_y(k_alpha phi) ...
    rot = posture_rotation(k_alpha * phi, 0.0)
    expected = (feet[[IDX[leg] for leg in stance]] + [-S / 2, 0, 0]) @ rot.T
    np.testing.assert_allclose(stance_end, expected, atol=1e-12)
    # ... so the remaining torso-to-ground pitch is (1 - k_alpha) phi.
    residual, _ = torso_deviation_from_plane(fit_plane(stance_end).normal)
    assert residual == pytest.approx((1 - k_alpha) * phi, abs=1e-9)
    if k_alpha > 0:  # front foot pushed down relative to the rear one: the nose comes up
        rf, rr = IDX["RF"], IDX["RR"]
        assert end[rf, 2] - end[rr, 2] < feet[rf, 2] - feet[rr, 2]


@pytest.mark.parametrize("k_beta", [0.0, 0.4, 1.0])
def test_roll_correction_has_the_right_sign_and_size(k_beta):
    psi = math.radians(-5.0)  # ground rises to the left: torso's left side is low relative to it
    feet = _plane_feet(b=-math.tan(psi))
    stance = TRIPODS[1]
    ctrl = AthenaPostureController(k_beta=k_beta)
    end = _run_phase(ctrl, feet, stance)
    est = ctrl.last_estimate
    assert est.delta_roll == pytest.approx(psi, abs=1e-12)
    assert est.delta_pitch == pytest.approx(0.0, abs=1e-12)
    stance_end = end[[IDX[leg] for leg in stance]]
    _, residual = torso_deviation_from_plane(fit_plane(stance_end).normal)
    assert residual == pytest.approx((1 - k_beta) * psi, abs=1e-9)
    if k_beta > 0:  # left foot pushed down relative to the right: the left side comes up
        lm, rf = IDX["LM"], IDX["RF"]
        assert end[lm, 2] - end[rf, 2] < feet[lm, 2] - feet[rf, 2]


def test_full_gains_level_the_torso_on_a_combined_tilt_to_first_order():
    feet = _plane_feet(a=math.tan(math.radians(5)), b=math.tan(math.radians(4)))
    ctrl = AthenaPostureController(k_alpha=1.0, k_beta=1.0)
    end = _run_phase(ctrl, feet, TRIPODS[1])
    pitch, roll = torso_deviation_from_plane(fit_plane(end[[IDX[x] for x in TRIPODS[1]]]).normal)
    assert abs(pitch) < math.radians(0.2) and abs(roll) < math.radians(0.2)


@pytest.mark.parametrize("kz", [0.0, 0.5, 1.0])
def test_height_correction_lowers_the_feet_when_the_torso_is_low(kz):
    feet = kin.standing_foot_positions()
    low = ATHENA.standing_torso_height - 0.02
    ctrl = AthenaPostureController(kz=kz, stride=0.0)
    end = _run_phase(ctrl, feet, TRIPODS[1], height=low)
    assert ctrl.last_estimate.delta_z == pytest.approx(-0.02)
    # Swing end point (eq. 27) and stance end point (eq. 30) both move by k_z delta_z.
    np.testing.assert_allclose(end[:, 2] - feet[:, 2], -0.02 * kz, atol=1e-12)
    np.testing.assert_allclose(end[:, :2], feet[:, :2], atol=1e-12)


@pytest.mark.parametrize("reading", [float("nan"), -1.0])
def test_missing_height_reading_means_no_height_correction(reading):
    ctrl = AthenaPostureController(kz=1.0)
    _run_phase(ctrl, kin.standing_foot_positions(), TRIPODS[1], height=reading)
    assert ctrl.last_estimate.delta_z == 0.0


# ----- contact rules of eq. (24) -----------------------------------------------------------
def test_all_feet_in_contact_uses_the_stance_tripod():
    ctrl = AthenaPostureController()
    ctrl.step(_sensors(kin.standing_foot_positions(), LEG_NAMES))
    assert ctrl.last_estimate.plane_legs == TRIPODS[1]
    assert ctrl.last_estimate.contact_legs == LEG_NAMES


def test_a_landing_leg_without_contact_is_extended_until_it_touches():
    feet = kin.standing_foot_positions()
    ctrl = AthenaPostureController(touchdown_wait=1, extend_step=0.002, ground_search="always")
    missing = "RR"
    others = [leg for leg in LEG_NAMES if leg != missing]
    z0 = feet[IDX[missing], 2]
    ctrl.step(_sensors(feet, others))  # first tick: hold
    assert ctrl.phase_index == -1
    assert ctrl.commanded_feet[IDX[missing], 2] == pytest.approx(z0)
    for k in range(1, 4):  # then extend 2 mm per tick; the phase waits
        ctrl.step(_sensors(feet, others))
        assert ctrl.phase_index == -1
        assert ctrl.commanded_feet[IDX[missing], 2] == pytest.approx(z0 - 0.002 * k)
    np.testing.assert_allclose(
        ctrl.commanded_feet[[IDX[x] for x in others]], feet[[IDX[x] for x in others]]
    )
    touched = ctrl.commanded_feet
    ctrl.step(_sensors(touched, LEG_NAMES))  # contact: the phase starts
    assert ctrl.phase_index == 0
    assert ctrl.last_estimate.extension == pytest.approx(0.006)
    assert ctrl.last_estimate.plane_legs == TRIPODS[1]


def test_a_leg_that_never_touches_falls_back_to_the_widest_contact_triple():
    feet = kin.standing_foot_positions()
    ctrl = AthenaPostureController(
        touchdown_wait=0, extend_step=0.01, max_extension=0.03, ground_search="always"
    )
    contacts = ("LF", "LM", "LR", "RF")  # RR (a stance leg) and RM hang in the air
    for _ in range(3):
        ctrl.step(_sensors(feet, contacts))
        assert ctrl.phase_index == -1
    ctrl.step(_sensors(feet, contacts))
    est = ctrl.last_estimate
    assert est.extension == pytest.approx(0.03)
    assert set(est.plane_legs) == {"LF", "LR", "RF"}  # the largest triangle among the contacts


@pytest.mark.parametrize(
    ("ground_search", "gains", "searches"),
    [
        ("auto", (0.0, 0.0, 0.0), False),  # the paper's non-adaptive simple control
        ("auto", (1.0, 0.0, 0.0), False),  # height control alone needs no plane
        ("auto", (0.0, 0.3, 0.0), True),
        ("auto", (0.0, 0.0, 0.3), True),
        ("always", (0.0, 0.0, 0.0), True),
        ("never", (0.6, 0.4, 0.4), False),
    ],
)
def test_ground_search_runs_when_the_phase_uses_the_plane(ground_search, gains, searches):
    kz, ka, kb = gains
    ctrl = AthenaPostureController(
        kz=kz, k_alpha=ka, k_beta=kb, touchdown_wait=0, ground_search=ground_search
    )
    feet = kin.standing_foot_positions()
    ctrl.step(_sensors(feet, [leg for leg in LEG_NAMES if leg != "RR"]))
    assert ctrl.phase_index == (-1 if searches else 0)


def test_fewer_than_three_contacts_after_extension_gives_no_tilt_correction():
    ctrl = AthenaPostureController(k_alpha=1, k_beta=1, touchdown_wait=0, max_extension=0.004)
    feet = _plane_feet(a=0.1)
    for _ in range(3):
        ctrl.step(_sensors(feet, ("LM", "RF")))
    est = ctrl.last_estimate
    assert est.plane_legs == ()
    assert est.delta_pitch == 0.0 and est.delta_roll == 0.0


def test_random_triple_choice_follows_the_generator():
    def choices(seed):
        ctrl = AthenaPostureController(rng=np.random.default_rng(seed))
        feet = kin.standing_foot_positions()
        out = []
        for phase in range(6):
            stance = TRIPODS[(phase + 1) % 2]
            ctrl.step(_sensors(feet, LEG_NAMES))
            out.append(ctrl.last_estimate.plane_legs)
            for _ in range(ctrl.ticks_per_phase - 1):
                ctrl.step(_sensors(feet, stance))
        return out

    assert choices(3) == choices(3)
    assert len(set(choices(3) + choices(4))) > 2  # not always the same triple


# ----- gains and inputs --------------------------------------------------------------------
def test_gains_set_mid_phase_take_effect_at_the_next_phase():
    ctrl = AthenaPostureController(kz=0.1)
    feet = kin.standing_foot_positions()
    ctrl.step(_sensors(feet, TRIPODS[1]))
    assert ctrl.last_estimate.gains == (0.1, 0.0, 0.0)
    ctrl.set_gains(0.8, 0.6, 0.0)
    assert not ctrl.at_phase_start
    for _ in range(ctrl.ticks_per_phase - 1):
        ctrl.step(_sensors(feet, TRIPODS[1]))
    assert ctrl.last_estimate.gains == (0.1, 0.0, 0.0)
    assert ctrl.at_phase_start
    ctrl.step(_sensors(feet, TRIPODS[0]))
    assert ctrl.last_estimate.gains == (0.8, 0.6, 0.0)
    assert ctrl.ticks_per_cycle == 40


def test_cycle_clock_counts_two_phases_per_cycle():
    ctrl = AthenaPostureController()
    feet = kin.standing_foot_positions()
    n = ctrl.ticks_per_phase
    seen = []
    for k in range(2 * ctrl.ticks_per_cycle):
        seen.append((ctrl.at_cycle_start, ctrl.cycle_phase, ctrl.next_phase_index))
        ctrl.step(_sensors(feet, TRIPODS[(k // n + 1) % 2]))
    starts = [k for k, (start, _, _) in enumerate(seen) if start]
    assert starts == [0, ctrl.ticks_per_cycle]
    assert [p for _, p, _ in seen[: 2 * n]] == pytest.approx([k / (2 * n) for k in range(2 * n)])
    assert seen[n][2] == 1 and seen[n - 1][2] == 0


@pytest.mark.parametrize("start_from", ["measured", "commanded", "measured_height"])
def test_phase_start_rules_take_the_foot_positions_they_name(start_from):
    """Encoders report every foot 5 mm further forward and 4 mm lower than commanded."""
    ctrl = AthenaPostureController(start_from=start_from)
    commanded = kin.standing_foot_positions()
    measured = commanded + [0.005, 0.0, -0.004]
    ctrl.step(_sensors(measured, TRIPODS[1]))
    start = ctrl.commanded_feet  # after the first tick: start + 1/20 of the path
    swing = [IDX[leg] for leg in TRIPODS[0]]
    u = 1 / ctrl.ticks_per_phase
    expected_start = {
        "measured": measured,
        "commanded": commanded,
        "measured_height": np.column_stack([commanded[:, :2], measured[:, 2]]),
    }[start_from]
    stance = [IDX[leg] for leg in TRIPODS[1]]
    np.testing.assert_allclose(
        start[stance], expected_start[stance] + [-u * S / 2, 0, 0], atol=1e-12
    )
    np.testing.assert_allclose(
        start[swing, :2],
        expected_start[swing, :2]
        + [S / 2 * (3 * u * (1 - u) ** 2 / 4 + 3 * u * u * (1 - u) * 3 / 4 + u**3), 0],
        atol=1e-12,
    )


def test_bad_arguments_raise_clear_errors():
    with pytest.raises(ValueError, match="k_alpha"):
        AthenaPostureController(k_alpha=1.5)
    with pytest.raises(ValueError, match="kz"):
        AthenaPostureController().set_gains(-0.1, 0, 0)
    with pytest.raises(ValueError, match="whole number"):
        AthenaPostureController(control_dt=0.03)
    with pytest.raises(ValueError, match="start_from"):
        AthenaPostureController(start_from="guess")
    ctrl = AthenaPostureController()
    with pytest.raises(ValueError, match="joint_angles"):
        ctrl.step(AthenaSensors(np.zeros((6, 2)), np.zeros(6), 0.1))
    with pytest.raises(ValueError, match="foot_forces"):
        ctrl.step(AthenaSensors(np.zeros((6, 3)), np.zeros(5), 0.1))
    with pytest.raises(ValueError, match="g_z"):
        torso_deviation_from_plane([0, 0, -1])
    feet = np.tile([0.1, 0.1, -0.1], (6, 1))
    for bad_feet, bad_contact in ((feet[:4], np.ones(6, bool)), (feet, np.ones(4, bool))):
        with pytest.raises(ValueError, match=r"shape \(6, 3\).*\(6,\)"):  # not read past
            ctrl.ground_deviation(bad_feet, bad_contact, (0, 2, 4))
