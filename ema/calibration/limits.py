"""What every kind's calibration holds to: how many folds it holds out, the evidence from which it names an effect
(``noise_z``), and how many effects it adopts. A kind's calibration reads these; none restates them."""

FOLDS = 5  # each window's samples in five folds, each predicted from the other four (a held-out score)
NAME_Z = 6.0  # an effect is named where what it explains stands this many stds of what noise alone explains
MAX_EFFECTS = 2  # effects adopted into the model at most, one at a time, each judged given the ones before
# A floor under the std of what noise-only copies explain: a candidate that explains exactly nothing on every copy
# (a grid holding "no effect") would have a zero std, and any drop would be infinitely significant.
MIN_NULL_STD = 1e-3


def noise_z(drop: float, null_mean: float, null_std: float) -> float:
    """The evidence for a candidate: its held-out drop on the logs in stds of the drops it gives on noise-only copies
    (their mean ``null_mean``, their std ``null_std``, floored at ``MIN_NULL_STD``); named at ``NAME_Z``."""
    return (drop - null_mean) / max(null_std, MIN_NULL_STD)
