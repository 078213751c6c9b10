"""``simulate_batch``: validate, pack constants, allocate, run the kernel, return the recorded signals."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np

from ema.kinds.rotary.simulator import kernels
from ema.kinds.rotary.simulator.effects import TABLE_VARIABLES, EffectSet
from ema.kinds.rotary.simulator.loads import Load, load_model
from ema.model import runtime
from ema.model.aircraft import FlightCondition, HingeGeometry
from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ, SAMPLE_RATE_RANGE_HZ
from ema.model.checks import InputError, finite_array, in_range
from ema.model.params import DriveConstants, HealthParams, load_factors

VECTOR_LANES = 8  # float64 in one AVX-512 register
LANE_MULTIPLE = VECTOR_LANES * runtime.INTERLEAVE  # one iteration of the vectorized lane loop
MAX_LANES = 3 * LANE_MULTIPLE  # simulations advanced in lock-step; fewer lanes pay more per-step loop overhead
MIN_VECTOR_LANES = LANE_MULTIPLE  # fewer lanes take the lane loop's scalar path, several times the cost per lane
# A group's fixed cost per step, in lanes' worth: one thread, 24 lanes cost 3.0-3.4 ns a lane-step, 48 and 72 2.8.
GROUP_OVERHEAD_LANES = 6
# Past the end stops a command only saturates the speed reference: ω_ref = sat(G_P·(θ_cmd − θ_u)) is
# already ±ω_max once θ_cmd is ω_max/G_P ≈ 0.37° beyond them, so clipping there changes nothing.
COMMAND_MARGIN_DEG = 1.0
INITIAL_MARGIN = 1.1  # a first state may stand this far past the drive's saturations (read through noise)


@dataclass(frozen=True)
class InitialState:
    """Where every simulation of a batch starts (the first sample of a window)."""

    position_deg: float = 0.0  # elevator deflection θ_u [deg]
    motor_speed_radps: float = 0.0  # ω_m [rad/s]
    current_a: float = 0.0  # phase current I [A]


@dataclass(frozen=True)
class BatchResult:
    """Recorded signals, each (n_simulations, n_samples) of interval means at ``sample_rate_hz``.

    ``signals`` holds the five window signals; ``loss_torque_nm`` is the true transmission loss
    (dry + viscous + cogging friction at the motor shaft), what the residual torque reconstructs.
    """

    sample_rate_hz: float
    signals: dict[str, np.ndarray]
    loss_torque_nm: np.ndarray
    health: HealthParams
    effects: EffectSet = field(default_factory=EffectSet)

    @property
    def n_samples(self) -> int:
        return self.loss_torque_nm.shape[1]

    def simulation(self, index: int) -> dict[str, np.ndarray]:
        """One simulation's signals, as a window would hold them."""
        return {name: values[index] for name, values in self.signals.items()}


def kernel_constants(drive: DriveConstants, effects: EffectSet) -> kernels.KernelConstants:
    """The step's constants with the effects folded in (derived once per batch)."""
    gain = effects.get("torque_constant", "gain")
    sensor_gain = effects.get("current_sensor_gain", "gain")
    stribeck_speed = effects.get("stribeck", "speed_radps")
    table = effects.table
    h_over_l = drive.step_s / drive.inductance_h
    return kernels.KernelConstants(
        step_s=drive.step_s,
        step_over_gear=drive.step_s / drive.gear_ratio,
        position_gain=drive.position_gain_per_s,
        max_speed_ref=drive.max_motor_speed_radps,
        speed_gain_over_kt=drive.speed_gain_nms / drive.torque_constant_nm_per_a / sensor_gain,
        max_current=drive.max_current_a / sensor_gain,
        voltage_step=h_over_l * drive.supply_voltage_v,
        current_decay=1.0 - h_over_l * drive.resistance_ohm,
        back_emf_step=h_over_l * gain * drive.torque_constant_nm_per_a,
        torque_constant=gain * drive.torque_constant_nm_per_a,
        max_torque=drive.max_motor_torque_nm,
        inverse_gear=1.0 / drive.gear_ratio,
        gear=drive.gear_ratio,
        step_over_inertia=drive.step_s / (drive.inertia_kgm2 * effects.get("inertia", "factor")),
        viscous=drive.viscous_nms + effects.get("viscous", "coefficient_nms"),
        half_backlash=0.5 * (drive.backlash_rad + effects.get("backlash", "extra_rad")),
        end_stop=float(np.radians(drive.end_stop_deg)),
        current_sensor_gain=sensor_gain,
        current_sensor_offset=effects.get("current_sensor_offset", "offset_a"),
        current_ref_shift=effects.get("current_sensor_offset", "offset_a") / sensor_gain,
        hinge_sensor_bias=effects.get("hinge_moment_bias", "bias_nm"),
        stribeck_amplitude=effects.get("stribeck", "amplitude_nm"),
        stribeck_inverse_speed=1.0 / stribeck_speed,
        position_friction=effects.get("position_friction", "amplitude_nm") / np.radians(drive.end_stop_deg),
        cogging_amplitude=effects.get("cogging", "amplitude_nm"),
        cogging_wavenumber=effects.get("cogging", "periods_per_rev") * drive.gear_ratio,
        cogging_phase=effects.get("cogging", "phase_rad"),
        table_variable=0 if table is None else TABLE_VARIABLES[table.variable],
        table_start=0.0 if table is None else table.start,
        table_step=1.0 if table is None else table.step,
        with_friction_effects=effects.get("stribeck", "amplitude_nm") != 0.0
        or effects.get("position_friction", "amplitude_nm") != 0.0
        or table is not None,
        with_cogging=effects.get("cogging", "amplitude_nm") != 0.0,
    )


def interval_steps(n_samples: int, sample_rate_hz: float, drive: DriveConstants) -> np.ndarray:
    """(n_samples,) steps of h in each log interval: interval k spans steps round(k/(f·h)) to round((k+1)/(f·h)).

    Any rate is exact: at 3 kHz the intervals hold 333 or 334 steps, as a logger's clock would.
    """
    rate = in_range("sample_rate_hz", sample_rate_hz, *SAMPLE_RATE_RANGE_HZ, "Hz")
    edges = np.round(np.arange(n_samples + 1) / (rate * drive.step_s)).astype(np.int64)
    return np.diff(edges)


def clipped_knots(command_knots_deg: np.ndarray, n_health: int, end_stop_deg: float) -> np.ndarray:
    """Knots checked for shape and finiteness, clipped where the controller saturates anyway."""
    knots = np.atleast_2d(finite_array("command_knots_deg", command_knots_deg))
    if knots.ndim != 2 or knots.shape[1] < 2:
        raise InputError("command_knots_deg", f"must be (n_samples + 1,) or (n, n_samples + 1), got {knots.shape}")
    if knots.shape[0] not in (1, n_health):
        raise InputError(
            "command_knots_deg", f"needs 1 command or one per simulation ({n_health}), got {knots.shape[0]}"
        )
    limit = end_stop_deg + COMMAND_MARGIN_DEG
    return np.clip(knots, -limit, limit)


def _checked_initial(initial: InitialState, drive: DriveConstants) -> InitialState:
    """``initial``, within the end stops and ``INITIAL_MARGIN`` of the drive's speed and current saturations."""
    stop = drive.end_stop_deg
    speed, current = (INITIAL_MARGIN * limit for limit in (drive.max_motor_speed_radps, drive.max_current_a))
    in_range("initial.position_deg", initial.position_deg, -stop, stop, "deg")
    in_range("initial.motor_speed_radps", initial.motor_speed_radps, -speed, speed, "rad/s")
    in_range("initial.current_a", initial.current_a, -current, current, "A")
    return initial


def default_lanes(n_sims: int) -> int:
    """Lanes per group: of the sizes the vectorized lane loop runs whole (multiples of ``LANE_MULTIPLE`` from
    MIN_VECTOR_LANES to MAX_LANES; fewer lanes run scalar, at several times the cost per lane), the one that
    leaves the least work on the busiest thread, each group counted with its fixed cost
    (``GROUP_OVERHEAD_LANES``): 89 simulations on two threads run as two groups of 48, 500 as seven of 72.
    Below one register the lanes run scalar anyway: no padding."""
    if n_sims < VECTOR_LANES:
        return max(n_sims, 1)
    threads = runtime.threads()

    def busiest(lanes: int) -> tuple[int, int]:
        groups = -(-n_sims // lanes)
        rounds = -(-groups // threads)  # groups the busiest thread runs
        return rounds * (lanes + GROUP_OVERHEAD_LANES), -lanes

    return min(range(MIN_VECTOR_LANES, MAX_LANES + 1, LANE_MULTIPLE), key=busiest)


def run_groups(inputs: tuple, out: np.ndarray, lanes: int) -> None:
    """``kernels.run_group`` for every group of ``lanes`` simulations, on the simulator's thread pool
    (``runtime.map_on_pool``: inline with one thread or one group). ``inputs`` are the kernel's arguments
    before ``first``: its constants and its inputs."""

    def run(first: int) -> None:
        kernels.run_group(*inputs, first, lanes, out)  # type: ignore[call-arg]  # numba's Dispatcher

    runtime.map_on_pool(run, range(0, out.shape[1], lanes))


def _padded(values: np.ndarray, multiple: int) -> np.ndarray:
    """Repeat the last column so the simulation axis (last) is a multiple of ``multiple``."""
    missing = -values.shape[-1] % multiple
    if missing == 0:
        return np.ascontiguousarray(values)
    return np.concatenate([values, np.repeat(values[..., -1:], missing, axis=-1)], axis=-1)


_KEPT = threading.local()


def _recording(shape: tuple[int, int, int], reuse: bool) -> np.ndarray:
    """The kernel's output array: fresh, or with ``reuse`` this thread's kept one of that shape.

    The kernel writes each log interval's means across every simulation's row, pages apart: into
    fresh memory every one of those writes first faults its page in, which a batch recorded into
    memory it has written before does not pay (docs/benchmarks.md has the cost).
    """
    if not reuse:
        return np.empty(shape)
    kept = getattr(_KEPT, "out", None)
    if kept is None or kept.shape != shape:
        kept = _KEPT.out = np.empty(shape)
    return kept


def simulate_batch(
    command_knots_deg: np.ndarray,
    health: HealthParams,
    load: Load = FlightCondition(),
    initial: InitialState = InitialState(),
    sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ,
    effects: EffectSet = EffectSet(),
    *,
    drive: DriveConstants,
    hinge: HingeGeometry | None = None,
    lanes: int | None = None,
    reuse_output: bool = False,
) -> BatchResult:
    """Simulate one simulation per entry of ``health`` and record interval means at ``sample_rate_hz``.

    ``command_knots_deg`` is the command at the log-interval boundaries (see ``simulator.commands``):
    (n_samples + 1,) shared by the batch (Case 1) or (n_simulations, n_samples + 1) (Case 2).
    ``drive``: the drive's constants; ``hinge``: the airframe's hinge-moment model where ``load`` is a
    flight condition (the thesis's elevator by default). The 1 µs trajectory is never stored.
    Deterministic: the same inputs give the same output, whatever ``lanes`` (simulations per lock-step
    group; by default as many as keep every thread busy, up to 64) and whatever the thread budget.
    ``reuse_output``: record into this thread's kept buffer (``_recording``), for a caller that copies
    what it keeps: the result's arrays are overwritten by the next such call on the thread.
    """
    if not isinstance(health, HealthParams):
        raise InputError("health", f"must be HealthParams, got {type(health).__name__}")
    n_sims = len(health)
    knots = clipped_knots(command_knots_deg, n_sims, drive.end_stop_deg)
    _checked_initial(initial, drive)
    if not isinstance(effects, EffectSet):
        raise InputError("effects", f"must be an EffectSet, got {type(effects).__name__}")
    lanes = default_lanes(n_sims) if lanes is None else lanes
    if not 1 <= lanes <= 512:
        raise InputError("lanes", f"must be in [1, 512], got {lanes}")
    n_samples = knots.shape[1] - 1
    steps = interval_steps(n_samples, sample_rate_hz, drive)
    loads = load_model(load, 1.0 / sample_rate_hz, hinge)
    if len(loads.slow_table_nm) not in (0, n_samples):
        raise InputError("load", f"a logged load needs {n_samples} values, got {len(loads.slow_table_nm)}")

    k_aid, k_opp = load_factors(health.eta_o, drive.gear_ratio)
    per_sim = _padded(np.stack([health.fdj_nm, health.fsj_nm, k_aid, k_opp]), lanes)
    start = [np.radians(initial.position_deg), initial.motor_speed_radps, initial.current_a]
    initial_rows = np.repeat(np.array(start)[:, None], per_sim.shape[1], axis=1)
    out = _recording((kernels.N_RECORDED, per_sim.shape[1], n_samples), reuse_output)
    constants = kernel_constants(drive, effects)
    knots_rad = np.ascontiguousarray(np.radians(knots))
    table_nm = np.zeros(2) if effects.table is None else np.array(effects.table.values_nm)
    run_groups((constants, (table_nm, loads, per_sim, knots_rad, steps, initial_rows)), out, lanes)
    out = out[:, :n_sims]
    signals = {
        "position_deg": np.degrees(out[kernels.POSITION]),
        "motor_speed_radps": out[kernels.SPEED],
        "current_a": out[kernels.CURRENT],
        "hinge_moment_nm": out[kernels.HINGE],
        "command_deg": np.degrees(out[kernels.COMMAND]),
    }
    return BatchResult(sample_rate_hz, signals, out[kernels.LOSS], health, effects)
