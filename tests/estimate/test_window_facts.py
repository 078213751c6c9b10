"""An estimate's ``window`` part: what every kind's says, and a rotary window's prepare stage's own facts in its own
class; an answer written before the split (every kind's with the rotary's facts at their defaults) still reads."""

from ema.estimate.documents.window_facts import RotaryWindowInfo, WindowInfo, window_info_from

SHARED = {
    "n_samples": 2000,
    "duration_s": 2.0,
    "sample_rate_hz": 1000.0,
    "processed_rate_hz": 1000.0,
    "command_clipped_fraction": 0.0,
    "sliding_fraction": 0.8,
}


def test_a_window_part_is_read_as_the_class_its_fields_are():
    assert type(window_info_from(SHARED)) is WindowInfo  # a servo's, a ball screw's, a slow rotary window's
    rotary = window_info_from({**SHARED, "hinge_gain": 1.02, "current_lag_s": 2.5e-4})
    assert type(rotary) is RotaryWindowInfo and rotary.hinge_gain == 1.02
    assert "hinge_gain" not in WindowInfo.model_fields and "hinge_gain" in RotaryWindowInfo.model_fields


def test_an_answer_written_with_every_field_still_reads_back():
    """Before the split every kind's answer carried the rotary's facts at their defaults: it reads, and says the
    same when written again."""
    defaults = {
        name: field.get_default(call_default_factory=True)
        for name, field in RotaryWindowInfo.model_fields.items()
        if name not in WindowInfo.model_fields
    }
    written_before = {**SHARED, **defaults}
    read = window_info_from(written_before)
    assert read.model_dump() == {**WindowInfo.model_validate(SHARED).model_dump(), **defaults}
