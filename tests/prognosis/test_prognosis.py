"""Trend and remaining life on synthetic actuator histories with a known truth."""

from pathlib import Path

import numpy as np
import pytest

from ema.model.actuator import THESIS
from ema.prognosis.backtest import backtest
from ema.prognosis.outlook import outlook
from ema.prognosis.rul import MIN_TREND_WINDOWS
from ema.prognosis.trend import Series, trend_of
from tests.prognosis.histories import History, history

THRESHOLD = 0.075  # FDJ +50 % of nominal
LAWS_SEEN = ("line", "doubling", "cube", "onset", "sinh")  # tests/prognosis/histories: none is a law of the code


def _outlook(h: History):
    series = Series("FDJ", h.hours, h.values, h.stds, [str(i) for i in range(len(h.hours))])
    return outlook(series, threshold=THRESHOLD, direction="above")


def _held(h: History, life) -> bool:
    return life.status == "crossing predicted" and life.rul_low <= h.true_life <= (life.rul_high or np.inf)


@pytest.mark.parametrize("law", LAWS_SEEN)
def test_the_remaining_life_holds_wear_of_laws_the_code_does_not_have(law):
    """20 windows over 190 h, crossing 20–60 h after the last, each with its std (tests/prognosis/histories):
    the 90 % interval holds the true life in most histories of every law, the median within 35 % of it. Of
    these 60 histories 53 were held and 58 close; a line alone held none of the accelerating ones."""
    held, close = 0, 0
    for seed in range(12):
        h = history(law, 3000 + seed)
        life = _outlook(h).life
        held += _held(h, life)
        close += life.rul is not None and abs(life.rul / h.true_life - 1) <= 0.35
    assert held >= 8 and close >= 10, (held, close)


def test_wear_that_speeds_up_is_said_and_its_earliest_crossing_given():
    h = history("doubling", 3100)
    seen = _outlook(h)
    assert seen.life.speeding_up and seen.life.rul_earliest <= seen.life.rul_low <= h.true_life
    assert seen.trend.laws["exponential"] + seen.trend.laws["power"] > 0.8  # the accelerating laws predicted best
    assert not _outlook(history("line", 3100)).life.speeding_up


def test_steady_actuators_raise_no_alarm():
    """A degradation is claimed at 95 %: on steady histories of every size, none here."""
    claims = [
        _outlook(history("steady", 3200 + seed, n=n, std=std)).life.status
        for seed in range(10)
        for n, std in ((10, 3e-4), (20, 1e-3), (60, 3e-4))
    ]
    assert claims.count("crossing predicted") == 0, claims


def test_outliers_do_not_move_the_outlook():
    h = history("line", 3300, n=40)
    values = h.values.copy()
    values[[5, 17, 29]] += 0.01  # three windows the model could not explain, 30 stds off
    clean, spoiled = _outlook(h).life, _outlook(History(h.hours, values, h.stds, h.true_life)).life
    assert spoiled.rul == pytest.approx(clean.rul, rel=0.25) and _held(h, spoiled)


def test_too_few_windows_and_a_crossed_threshold():
    two = Series("FDJ", np.array([0.0, 1.0]), np.array([0.05, 0.051]), np.array([1e-4, 1e-4]), ["a", "b"])
    few = outlook(two, threshold=THRESHOLD, direction="above").life
    assert few.status == "too few windows"
    h = history("line", 3400)
    crossed = _outlook(History(h.hours, h.values + 0.03, h.stds, 0.0)).life
    assert crossed.status == "already crossed" and crossed.rul == 0.0


def test_the_backtest_shows_past_forecasts_against_the_windows_since():
    h = history("cube", 3500, n=40)
    series = Series("FDJ", h.hours, h.values, h.stds, [f"w{i}" for i in range(40)])
    points = backtest(series, threshold=THRESHOLD, direction="above")
    assert [p.windows for p in points] == [20, 26, 32] and points[-1].later_windows == 8
    assert all(p.later_inside is not None and p.later_inside >= 0.7 for p in points)
    truth = h.hours[-1] + h.true_life  # the crossing dates move in on it as the windows come
    crossings = [p.crossing for p in points if p.crossing is not None]
    assert len(crossings) >= 2 and abs(crossings[-1] - truth) < abs(crossings[0] - truth)


@pytest.fixture(scope="module")
def one_estimate():
    from ema.estimate.config import PipelineConfig
    from ema.kinds.rotary.pipeline import estimate_window
    from ema.kinds.rotary.synthetic import synthetic_window
    from ema.model.params import HealthParams

    small = PipelineConfig(n_simulations=16, check_simulations=8, n_timesteps=50, hidden_units=8)
    return estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), small, actuator=THESIS)


def _float(value):
    return None if value is None else float(value)  # a document holds Python's floats (model_copy validates nothing)


def _history(estimate, ratios, stds, hours):
    from ema.prognosis.documents import Stored

    return [
        Stored(
            **estimate.model_copy(
                update={
                    "window_id": f"w{i}",
                    "window": estimate.window.model_copy(
                        update={
                            "flight_hours": float(h),
                            "hinge_aircraft_ratio": _float(r),
                            "hinge_aircraft_ratio_std": _float(s),
                        }
                    ),
                }
            ).model_dump(),
            id=i,
            stored_at="2026-11-23T00:00:00+00:00",
        )
        for i, (r, s, h) in enumerate(zip(ratios, stds, hours, strict=True))
    ]


def test_a_strain_gauge_drifting_against_the_aircraft_is_trended_and_said(one_estimate):
    from ema.prognosis.prognose import prognose

    rng = np.random.default_rng(5)
    hours = np.sort(rng.uniform(0, 200, 60))
    drifting = 1.0 - 0.0008 * hours + 0.01 * rng.normal(size=60)  # 0.84 after 200 h
    prognosis = prognose("tail-9", _history(one_estimate, drifting, np.full(60, 0.01), hours), actuator=THESIS)
    trend = prognosis.sensors["hinge_aircraft_ratio"]
    assert trend.slope_per_unit == pytest.approx(-0.0008, rel=0.15)
    assert {n.code for n in prognosis.notes} >= {"gauge_off_model", "gauge_drift"}  # off the model, and drifting
    steady = 1.0 + 0.01 * rng.normal(size=60)
    unknown = [None] * 20  # windows that read no ratio are left out of the trend
    history = _history(one_estimate, [*steady, *unknown], [*np.full(60, 0.01), *unknown], np.arange(80.0))
    prognosis = prognose("tail-9", history, actuator=THESIS)
    assert prognosis.sensors["hinge_aircraft_ratio"].n == 60
    assert not any(n.code.startswith("gauge") for n in prognosis.notes)


def test_a_constant_read_beside_the_health_is_trended_and_drawn(one_estimate, tmp_path):
    """A servo's mass, read window after window, is trended as the health is (no failure level, no life) and
    ``ema history --plot`` draws it."""
    from ema.cli.figures import prognosis_figure
    from ema.estimate.documents import ParameterEstimate
    from ema.prognosis.prognose import prognose

    rng = np.random.default_rng(8)
    hours = np.sort(rng.uniform(0, 100, 30))
    masses = 90.0 + 0.05 * hours + 0.2 * rng.normal(size=30)  # a load gaining 5 kg over 100 h
    history = _history(one_estimate, [None] * 30, [None] * 30, hours)
    for stored, mass in zip(history[:-1], masses, strict=False):  # the last window read no mass
        entry = ParameterEstimate(value=float(mass), std=0.2, nominal=90.0, drift_pct=None, unit="kg")
        stored.estimates.constants["mass_kg"] = entry
    prognosis = prognose("axis-1", history, actuator=THESIS)
    trend = prognosis.constants["mass_kg"]
    assert trend.n == 29 and trend.slope_per_unit == pytest.approx(0.05, rel=0.2)
    assert "mass_kg" not in prognosis.remaining_life
    pytest.importorskip("matplotlib")
    assert prognosis_figure(prognosis, "mass_kg", tmp_path / "mass.png", unit="kg").stat().st_size > 0


def test_the_actuators_j_m_is_its_windows_readings_and_a_replaced_part_is_said(one_estimate):
    from ema.estimate.documents.window_facts import InertiaReading
    from ema.prognosis.prognose import prognose

    def with_reads(factors):
        n = len(factors)
        history = _history(one_estimate, [1.0] * n, [0.01] * n, np.arange(n, dtype=float))
        for i, (stored, factor) in enumerate(zip(history, factors, strict=True)):
            read = None if factor is None else InertiaReading(factor=factor, std=0.002, window_ids=[stored.window_id])
            history[i] = stored.model_copy(update={"window": stored.window.model_copy(update={"inertia_read": read})})
        return prognose("tail-9", history, actuator=THESIS)

    rng = np.random.default_rng(6)
    steady = [None if i % 3 else float(1.06 + 0.002 * rng.normal()) for i in range(30)]  # every third reads J_M
    prognosis = with_reads(steady)
    assert prognosis.inertia.factor == pytest.approx(1.06, abs=0.002) and len(prognosis.inertia.window_ids) == 10
    assert not any(n.code.startswith("inertia") for n in prognosis.notes)
    replaced = [None if i % 3 else (1.06 if i < 15 else 1.0) + 0.002 * float(rng.normal()) for i in range(30)]
    prognosis = with_reads(replaced)  # J_M read 1.06x up to w12, 1.00x from w15 on
    assert prognosis.inertia.factor == pytest.approx(1.0, abs=0.003) and prognosis.inertia.window_ids[0] == "w15"
    assert any(n.code == "inertia_changed" and "w15" in n.text for n in prognosis.notes)
    scattered = [None if i % 3 else 1.06 + 0.01 * float(rng.normal()) for i in range(30)]  # each says ± 0.002
    prognosis = with_reads(scattered)
    assert len(prognosis.inertia.window_ids) == 10 and prognosis.inertia.std > 0.002  # no change: all, widened
    assert any(n.code == "inertia_scatter" for n in prognosis.notes)
    assert with_reads([None] * 5).inertia is None


@pytest.mark.parametrize("times", [[5.0], [5.0, 5.0], [5.0, 5.0, 5.0, 5.0]])
def test_windows_at_one_time_are_a_level_with_no_slope(times):
    n = len(times)
    series = Series("FDJ", np.array(times), np.full(n, 0.06), np.full(n, 1e-3), [str(i) for i in range(n)])
    trend = trend_of(series)
    assert trend.level == pytest.approx(0.06) and trend.slope_std is None
    assert trend.level_std == pytest.approx(1e-3 / np.sqrt(n))
    status = outlook(series, threshold=THRESHOLD, direction="above").life.status
    assert status == ("too few windows" if n < MIN_TREND_WINDOWS else "span too short")  # enough, at one time
    trend.model_dump_json()  # finite: JSON carries it


def test_a_prognosis_holds_its_kinds_own_parts_and_reads_back_as_its_class(one_estimate):
    """The rotary's J_M is its prognosis's own part (``RotaryPrognosis``); a ball screw's prognosis holds the shared
    parts alone, and each reads back as its class, as does one an earlier ema wrote with ``inertia`` in every kind's."""
    from ema.model.actuator import actuator_from_json
    from ema.prognosis.documents import PROGNOSIS, Prognosis, RotaryPrognosis
    from ema.prognosis.prognose import prognose

    history = _history(one_estimate, [1.0] * 6, [0.01] * 6, np.arange(6, dtype=float))
    rotary = prognose("tail-9", history, actuator=THESIS)
    screw = actuator_from_json((Path(__file__).parents[2] / "examples" / "ballscrew-rig" / "actuator.json").read_text())
    linear = prognose("rig", history, actuator=screw)
    assert type(rotary) is RotaryPrognosis and type(linear) is Prognosis and "inertia" not in linear.model_dump()
    for prognosis in (rotary, linear):
        assert PROGNOSIS.validate_json(prognosis.model_dump_json()) == prognosis
    earlier = {**linear.model_dump(mode="json"), "inertia": None}
    assert PROGNOSIS.validate_python(earlier) == RotaryPrognosis(**earlier)
    assert type(prognose("tail-9", [], actuator=THESIS)) is RotaryPrognosis  # its kind's, with no window yet
