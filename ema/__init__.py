"""ema: an onboard health monitor for electromechanical actuators.

Subpackages, each importing only those above it in this list:

- ``ema.model``: the physics and the public documents of a window and an actuator;
- ``ema.estimate``: one window -> ``ema-estimate/1``, a subpackage per stage;
- ``ema.calibration``: what the model misses, traced to a physical effect;
- ``ema.prognosis``: trends and remaining useful life;
- ``ema.service``: the HTTP service and the operator's pages;
- ``ema.cli``: the ``ema`` command line, replay, fleet and bench.
"""
