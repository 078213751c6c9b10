"""What a calibration answers, whatever the kind: the ``ema-calibration/1`` report and the figure it draws, the
rules every kind's selection holds to (``limits``) and the held-out folds a model is scored on (``held_out``).

Each kind's calibration (the rotary's loop that traces a residual to a missing effect, the servo's held-out
choice of load effects, the linear drive's learning) lives in its folder under ``ema.kinds``.
"""
