"""The flight envelope the model accepts (``docs/model.md``, the aircraft), as plain numbers.

Kept free of numpy so that the CLI's help can show them without importing the simulator.
"""

DEFAULT_AIRSPEED_MPS = 153.01  # 502 ft/s: the Stevens & Lewis F-16 trim the linearization is taken at
AIRSPEED_RANGE_MPS = (90.0, 215.0)
ALTITUDE_RANGE_M = (0.0, 10_000.0)
