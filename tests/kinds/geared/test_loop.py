"""The geared servo's closed loop: the fast path is the plain one, and the physics holds in closed forms."""

import numpy as np
import pytest

from ema.kinds.geared.loop import LANE_PARAMETERS, Run, lane_plain, pack, simulate_lanes, simulate_packed

LANE = dict(torque_per_volt=0.45, back_emf=1.0, inertia_kg_m2=0.026, error_gain_per_rad=0.2, duty_limit=0.97,
            min_duty=0.0, fdj_nm=0.13, viscous_nm_s_per_rad=0.02, k_opp=0.15, k_aid=0.1, static_friction_ratio=1.0,
            command_delay_s=0.0)  # fmt: skip


def lane(**changed: float) -> np.ndarray:
    return np.array([{**LANE, **changed}[name] for name in LANE_PARAMETERS])


def run(n: int = 400, *, on: np.ndarray | None = None, kp: float = 8.0, q0: float = 0.0, seed: int = 3) -> Run:
    rng = np.random.default_rng(seed)
    reference = np.repeat(rng.uniform(-1.2, 1.2, size=n // 50 + 1), 50)[:n]
    switch = np.ones(n, dtype=bool) if on is None else on
    return Run(reference, switch, 12.0 + 0.1 * rng.standard_normal(n), kp, 0.01, 0.8, 0.009, q0)


def test_the_kernel_is_the_plain_loop_line_by_line():
    on = np.ones(400, dtype=bool)
    on[250:320] = False  # a stretch with the motor off
    r = run(on=on)
    lanes = np.stack([lane(), lane(min_duty=0.02, command_delay_s=0.033), lane(static_friction_ratio=1.6, k_aid=0.9)])
    fast = simulate_lanes(r, lanes)
    for i, row in enumerate(lanes):
        positions, duties = lane_plain(r, row)
        np.testing.assert_allclose(fast.position_rad[i], positions, rtol=0, atol=1e-12)
        np.testing.assert_allclose(fast.duty_ratio[i], duties, rtol=0, atol=1e-12)


def test_packed_runs_are_each_run_alone():
    runs = [run(seed=s, kp=kp) for s, kp in ((1, 4.0), (2, 32.0), (5, 12.0))]
    packed = pack(runs)
    together = packed.split(simulate_packed(packed, lane(command_delay_s=0.02)))
    for r, q in zip(runs, together, strict=True):
        np.testing.assert_array_equal(q, simulate_lanes(r, lane(command_delay_s=0.02)[None, :]).position_rad[0])


def test_a_frictionless_pendulum_swings_at_its_own_frequency():
    """Motor off, no friction, a small swing: q̈ = −(M_g/J)·q, a period of 2π·√(J/M_g)."""
    n, dt = 3000, 0.001
    r = Run(np.zeros(n), np.zeros(n, dtype=bool), np.full(n, 12.0), 8.0, dt, 0.8, 0.009, 0.02)
    free = lane(fdj_nm=0.0, viscous_nm_s_per_rad=0.0, k_opp=0.0, k_aid=0.0)
    q = simulate_lanes(r, free[None, :]).position_rad[0]
    crossings = np.flatnonzero(np.diff(np.sign(q)) > 0) * dt
    period = 2 * np.pi * np.sqrt((0.026 + 0.009) / 0.8)
    assert np.mean(np.diff(crossings)) == pytest.approx(period, rel=0.01)


def test_a_friction_above_the_load_holds_the_shaft():
    n = 200
    r = Run(np.zeros(n), np.zeros(n, dtype=bool), np.full(n, 12.0), 8.0, 0.01, 0.8, 0.009, 0.3)  # motor off
    held = lane(fdj_nm=0.8 * np.sin(0.3) * 1.01, k_aid=0.0)
    assert np.all(simulate_lanes(r, held[None, :]).position_rad[0] == 0.3)


def test_the_aiding_efficiency_sets_how_fast_a_free_shaft_falls():
    """Motor off, at rest: the load aids the fall, q̈ = (|τ_g|·η_A − FDJ)/J down the slope."""
    r = Run(np.zeros(3), np.zeros(3, dtype=bool), np.full(3, 12.0), 8.0, 0.001, 0.8, 0.009, 1.0)
    for eta_a in (0.9, 0.6):
        q = simulate_lanes(r, lane(k_aid=1 - eta_a, fdj_nm=0.05)[None, :]).position_rad[0]
        falls = (q[1] - q[0]) / (1.5 * 0.001**2)  # BAM's step from rest moves q by q̈·Δt² + q̈·Δt²/2
        expected = -(0.8 * np.sin(1.0) * eta_a - 0.05) / (0.026 + 0.009)
        assert falls == pytest.approx(expected, rel=1e-9)
