"""The vocabulary: each named effect as a flexible family of equation-error columns (``ema.kinds.rotary.families``).

A named effect is not one rigid shape: friction against position is a bump of any centre and width over
the visited deflections (a localized spall as well as a broad rise), Stribeck friction a decay of any
speed scale and exponent, cogging a ripple of any order with the log's interval-mean attenuation
modelled (``ema.kinds.rotary.equations.cogging_columns``).

Coefficients map back to the simulator's parameters: in t = sgn(ω)(T_R − C_M·ω) a torque
constant g leaves (1 − g)·k_T·I, a current-sensor gain s leaves (1 − 1/s)·k_T·I_logged (the
same trace: twins, told apart by simulation in ``ema.kinds.rotary.twins``), a hinge-moment bias b
leaves sgn(ω)·b/n, an inertia ΔJ beyond J_M leaves sgn(ω)·ΔJ·dω/dt.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ema.kinds.rotary.equations import Equations
from ema.kinds.rotary.families import Family
from ema.kinds.rotary.simulator.effects import EffectSet, FrictionTable
from ema.model.params import DriveConstants

# A Stribeck curve exp(−(|ω|/ω_s)^δ): Tustin's δ = 1, the Gaussian δ = 2, a slower δ = ½ and the
# shapes between. A decay of another form matched by the wrong tail leaves friction at speed that goes
# into FDJ: with scales an octave apart it moved FDJ several times its noise, and a 1 − tanh decay
# lies between δ = 1 and δ = 1.5 (either alone leaves ~1 % of FDJ). Scales a quarter-octave apart and
# exponents a quarter apart follow a monotone decay closely enough that FDJ stays put.
STRIBECK_GRID = tuple(
    (float(w), d) for d in (0.5, 0.75, 1.0, 1.25, 1.5, 2.0) for w in np.round(np.geomspace(10.0, 640.0, 25), 1)
)  # (ω_s [rad/s], δ)
COGGING_ORDERS = tuple(float(p) for p in range(1, 49))
BUMP_WIDTHS_DEG = (0.75, 1.5, 3.0, 6.0)  # a spall's half-width, as a Gaussian's std
BUMP_SPACING_DEG = 0.5  # centres every half degree over the visited deflections
SPEED_TABLE = np.arange(0.0, 710.0, 10.0)  # |ω| grid [rad/s] a speed curve is tabulated on for the simulator
POSITION_TABLE = np.radians(np.arange(-30.0, 30.05, 0.1))  # θ_u grid a position curve is tabulated on


def _stribeck(speed_radps: np.ndarray, shape: tuple[float | np.ndarray, float | np.ndarray]) -> np.ndarray:
    """exp(−(|ω|/ω_s)^δ) for shape (ω_s, δ); arrays of shapes broadcast against the speeds."""
    scale, exponent = shape
    return np.exp(-((speed_radps / scale) ** exponent))


def _stribeck_stacked(e: Equations) -> np.ndarray:
    scales, exponents = (np.array(v)[None, :] for v in zip(*STRIBECK_GRID, strict=True))
    return _stribeck(e.variables["speed_radps"][:, None], (scales, exponents))[..., None]


def _stribeck_term(beta: np.ndarray, shape: tuple[float, float]) -> EffectSet:
    values = np.clip(beta[0] * _stribeck(SPEED_TABLE, shape), -0.5, 0.5)
    return EffectSet(table=FrictionTable("speed", 0.0, float(SPEED_TABLE[1]), tuple(values)))


def _bump(x: np.ndarray, where: tuple[float, float]) -> np.ndarray:
    centre, width = where
    return np.exp(-0.5 * ((x - centre) / width) ** 2)


def _bump_stacked(e: Equations, grid: tuple[tuple[float, float], ...]) -> np.ndarray:
    centres, widths = (np.array(v)[None, :] for v in zip(*grid, strict=True))
    x = e.variables["position_rad"][:, None]
    return np.exp(-0.5 * ((x - centres) / widths) ** 2)[:, :, None]


def _bump_term(beta: np.ndarray, where: tuple[float, float]) -> EffectSet:
    values = np.clip(beta[0] * _bump(POSITION_TABLE, where), -0.5, 0.5)
    step = float(POSITION_TABLE[1] - POSITION_TABLE[0])
    return EffectSet(table=FrictionTable("position", float(POSITION_TABLE[0]), step, tuple(values)))


def bump_grid(position_rad: np.ndarray) -> tuple[tuple[float, float], ...]:
    """(centre, width) pairs: centres every BUMP_SPACING_DEG over the visited deflections."""
    low, high = np.degrees(np.quantile(position_rad, [0.01, 0.99]))
    centres = np.radians(np.arange(low, high + BUMP_SPACING_DEG, BUMP_SPACING_DEG))
    return tuple((float(c), float(np.radians(w))) for c in centres for w in BUMP_WIDTHS_DEG)


GAINS = tuple(float(g) for g in np.round(np.arange(0.70, 1.3025, 0.005), 3))


def _gain_family(name: str, true_over_logged: Callable[[np.ndarray], np.ndarray], drive: DriveConstants) -> Family:
    """A gain on the current the model reads as torque, k_T's or the current sensor's: one family each, the
    grid's gains mapped by ``true_over_logged`` to the true torque's ratio to the model's."""

    def shift(e: Equations, gains: np.ndarray) -> np.ndarray:
        return _torque_shift(e, true_over_logged(gains), drive)

    def term(gain: float) -> EffectSet | None:
        return EffectSet({name: {"gain": gain}}) if 0.7 <= gain <= 1.3 else None

    return _sized(name, "current_a", shift, sizes=GAINS, parameter="gain", term=term)


def _torque_shift(e: Equations, true_over_logged: np.ndarray, drive: DriveConstants) -> np.ndarray:
    """(m, G): what T_R takes for friction when the motor's true torque is sat(r·k_T·I) and the model
    assumes sat(k_T·I), for each ratio r of a grid, as t sees it (times sgn ω). Linear in the
    current until the saturation, which a current-sensor gain below 1 reaches (the loop holds the
    *logged* current at I_max: the true one is above it)."""
    limit, k_t = drive.max_motor_torque_nm, drive.torque_constant_nm_per_a
    torque = k_t * e.variables["current_unsigned_a"][:, None]
    shift = torque * true_over_logged[None, :]  # the true torque, then the shift: one (m, G) array
    np.clip(shift, -limit, limit, out=shift)
    np.subtract(np.clip(torque, -limit, limit), shift, out=shift)
    return np.multiply(shift, e.variables["direction"][:, None], out=shift)


CURRENT_OFFSETS_A = tuple(float(o) for o in np.round(np.arange(-1.5, 1.5025, 0.005), 3))


def _offset_term(offset_a: float) -> EffectSet | None:
    return EffectSet({"current_sensor_offset": {"offset_a": offset_a}}) if abs(offset_a) <= 5.0 else None


def _offset_shift(e: Equations, offsets_a: np.ndarray, drive: DriveConstants) -> np.ndarray:
    """(m, G): what T_R takes for friction when the current sensor reads o too high, for each o of a grid, as t
    sees it (times sgn ω): the true current is the logged one less o, and the motor's torque is cut at its
    peak (the loop holds the *logged* current at I_max)."""
    limit, k_t = drive.max_motor_torque_nm, drive.torque_constant_nm_per_a
    current = e.variables["current_unsigned_a"][:, None]
    shift = current - offsets_a[None, :]  # the true current, then its torque, then the shift: one (m, G) array
    np.multiply(k_t, shift, out=shift)
    np.clip(shift, -limit, limit, out=shift)
    np.subtract(np.clip(k_t * current, -limit, limit), shift, out=shift)
    return np.multiply(shift, e.variables["direction"][:, None], out=shift)


HINGE_BIASES_NM = tuple(float(b) for b in np.arange(-150.0, 152.5, 2.5))


def _hinge_columns(e: Equations, bias_nm: float, gear: float) -> np.ndarray:
    """A hinge-moment sensor reading b too high leaves sgn(ω)·b/n in t, and moves the load the aiding
    and opposing columns are built from: with the load corrected by b, (a, o) change, and where the
    corrected load changes sign a sample even swaps columns. So for each b of a grid the columns
    are sgn(ω) and the change of a and o (their coefficients then come out near b/n, k_aid, k_opp)."""
    direction = e.variables["direction"]
    load = e.variables["load_nm"] * direction  # smoothed T_ext as read (a constant bias passes the reading)
    corrected = load - bias_nm / gear

    def split(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        aiding = t * direction > 0
        return np.abs(t) * aiding, np.abs(t) * ~aiding

    (a0, o0), (a1, o1) = split(load), split(corrected)
    return np.stack([direction, a1 - a0, o1 - o0], axis=1)


def _hinge_shift(e: Equations, bias_nm: float, gear: float) -> np.ndarray:
    """(m, 2): the change of (a, o) when the load is corrected by the bias."""
    return _hinge_columns(e, bias_nm, gear)[:, 1:]


def _hinge_stacked(e: Equations, gear: float) -> np.ndarray:
    """_hinge_columns for every bias of the grid: (m, G, 3)."""
    direction = e.variables["direction"][:, None]
    load = (e.variables["load_nm"] * e.variables["direction"])[:, None]
    corrected = load - np.array(HINGE_BIASES_NM)[None, :] / gear
    aiding0, aiding1 = load * direction > 0, corrected * direction > 0
    a = np.abs(corrected) * aiding1 - np.abs(load) * aiding0
    o = np.abs(corrected) * ~aiding1 - np.abs(load) * ~aiding0
    return np.stack([np.broadcast_to(direction, a.shape), a, o], axis=2)


def _cogging_parameters(b: np.ndarray, order: float) -> dict[str, float]:
    return {
        "amplitude_nm": float(np.hypot(b[0], b[1])),
        "periods_per_rev": order,
        "phase_rad": float(np.arctan2(b[1], b[0])),
    }


def named_families(measured: Equations, drive: DriveConstants) -> list[Family]:
    """The vocabulary, shaped on the measured window (a bump's centres span what it visited)."""
    return _speed_families() + _drive_families(drive) + _where_families(measured, drive.gear_ratio)


def _speed_families() -> list[Family]:
    """Friction that follows the speed: viscous, and a Stribeck decay of any scale and exponent."""
    return [
        Family(
            "viscous",
            "speed_radps",
            True,
            lambda e, g: e.variables["speed_radps"][:, None],
            lambda b, g: {"coefficient_nms": float(b[0])},
            lambda b, g: EffectSet({"viscous": {"coefficient_nms": float(np.clip(b[0], -5e-5, 5e-3))}}),
        ),
        Family(
            "stribeck",
            "speed_radps",
            True,
            lambda e, g: _stribeck(e.variables["speed_radps"], g)[:, None],
            lambda b, g: {"amplitude_nm": float(b[0]), "decay_speed_radps": g[0], "exponent": g[1]},
            _stribeck_term,
            STRIBECK_GRID,
            stacked=_stribeck_stacked,
        ),
    ]


def _drive_families(drive: DriveConstants) -> list[Family]:
    """What the drive's constants or its current sensor may differ by: k_T, the sensor's gain or offset, J_M."""
    return [
        _gain_family("torque_constant", lambda gains: gains, drive),
        _gain_family("current_sensor_gain", lambda gains: 1.0 / gains, drive),
        _sized(
            "current_sensor_offset",
            "direction",
            lambda e, offsets: _offset_shift(e, offsets, drive),
            sizes=CURRENT_OFFSETS_A,
            parameter="offset_a",
            term=_offset_term,
        ),
        Family(
            "inertia",
            "acceleration_radps2",
            True,
            lambda e, g: e.variables["acceleration_radps2"][:, None],
            lambda b, g: {"factor": 1.0 + float(b[0]) / drive.inertia_kgm2},
            lambda b, g: EffectSet({"inertia": {"factor": float(np.clip(1.0 + b[0] / drive.inertia_kgm2, 0.5, 2.0))}}),
        ),
    ]


def _sized(
    name: str,
    follows: str,
    shift: Callable[[Equations, np.ndarray], np.ndarray],
    *,
    sizes: tuple[float, ...],
    parameter: str,
    term: Callable[[float], EffectSet | None],
) -> Family:
    """A family whose grid is the effect's ``sizes`` (the report's ``parameter``) and whose trace the physics fixes
    (coefficient 1): ``shift`` maps an array of sizes to the (m, G) shifts."""
    return Family(
        name,
        follows,
        True,
        lambda e, g: shift(e, np.array([g])),
        lambda b, g: {parameter: g},
        lambda b, g: term(g),
        sizes,
        sized=True,
        stacked=lambda e: shift(e, np.array(sizes))[..., None],
        offset=True,
    )


def _where_families(measured: Equations, n: float) -> list[Family]:
    """What follows the load or where the shaft is: a hinge-moment sensor's bias, friction at a place of
    the travel (a bump), cogging."""
    bumps = bump_grid(measured.variables["position_rad"])
    return [
        Family(
            "hinge_moment_bias",
            "direction",
            True,
            lambda e, g: _hinge_columns(e, g, n),
            lambda b, g: {"bias_nm": float(b[0]) * n, "grid_bias_nm": g},
            lambda b, g: EffectSet({"hinge_moment_bias": {"bias_nm": float(np.clip(b[0] * n, -500, 500))}}),
            HINGE_BIASES_NM,
            sized=True,
            stacked=lambda e: _hinge_stacked(e, n),
            base_shift=lambda e, g: _hinge_shift(e, g, n),
            free_columns=1,
        ),
        Family(
            "position_friction",
            "position_rad",
            True,
            lambda e, g: _bump(e.variables["position_rad"], g)[:, None],
            lambda b, g: {
                "amplitude_nm": float(b[0]),
                "centre_deg": float(np.degrees(g[0])),
                "width_deg": float(np.degrees(g[1])),
            },
            _bump_term,
            bumps,
            stacked=lambda e: _bump_stacked(e, bumps),
        ),
        Family(
            "cogging",
            "motor_angle_rad",
            True,
            lambda e, g: e.cogging[g],
            _cogging_parameters,
            lambda b, g: EffectSet(
                {"cogging": {**_cogging_parameters(b, g), "amplitude_nm": float(min(np.hypot(b[0], b[1]), 0.5))}}
            ),
            COGGING_ORDERS,
            stacked=lambda e: np.stack([e.cogging[p] for p in COGGING_ORDERS], axis=1),
        ),
    ]
